"""Compiled evaluation of OpenDRIVE reference lines made of lines and arcs, and of elevation
profiles: the one definition of these shapes (``Geometry.pose`` evaluates lines and arcs with
it; the scenario engine places its actors with it in one compiled pass per road).

Frames and units: network metres; road s along the reference line; headings in radians
counter-clockwise from +x; curvature 1/m (positive: turning left).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from hiyari.jit import njit
from hiyari.net.road.lane_profile import cubic_at

if TYPE_CHECKING:
    from hiyari.net.road.opendrive_lanes import Road

#: Curvature below which an arc is evaluated as a line, 1/m.
STRAIGHT = 1e-15


#: Columns of a PlanView's geometry rows: start s (m), start x, y (m), heading (rad), its cos
#: and sin, curvature (1/m; 0 for a line).
G_S0, G_X, G_Y, G_HDG, G_COS, G_SIN, G_K = range(7)


@dataclass(frozen=True)
class PlanView:
    """A road's reference line made of lines and arcs (``geom``: a row per geometry, sorted
    by s, columns ``G_*``) and elevation records (start s, cubic coefficients)."""

    length: float
    geom: np.ndarray
    elev_s0: np.ndarray
    elev_c: np.ndarray

    def arrays(self) -> tuple:
        """The arguments of :func:`road_pose_at` before s and t."""
        return self.length, self.geom, self.elev_s0, self.elev_c


def plan_view(road: Road) -> PlanView | None:
    """The PlanView of ``road``; None when a geometry is neither a line nor an arc."""
    if any(g.kind not in ("line", "arc") for g in road.geometries):
        return None
    rows = [
        (g.s0, g.x, g.y, g.hdg, math.cos(g.hdg), math.sin(g.hdg),
         g.params[0] if g.kind == "arc" else 0.0)
        for g in road.geometries
    ]  # fmt: skip
    return PlanView(
        road.length,
        np.array(rows, dtype=float).reshape(-1, 7),
        np.array([e.s0 for e in road.elevation], dtype=float),
        np.array([(e.a, e.b, e.c, e.d) for e in road.elevation], dtype=float).reshape(-1, 4),
    )


@njit(cache=True)
def line_arc_pose(
    x0: float, y0: float, hdg: float, c0: float, s0: float, k: float, u: float
) -> tuple[float, float, float]:
    """(x, y, heading) at ``u`` m along a line (``k`` = 0) or an arc of curvature ``k`` that
    starts at (``x0``, ``y0``) with heading ``hdg`` (``c0``, ``s0``: its cos and sin)."""
    if abs(k) < STRAIGHT:
        return x0 + u * c0, y0 + u * s0, hdg
    h = hdg + k * u
    return x0 + (math.sin(h) - s0) / k, y0 - (math.cos(h) - c0) / k, h


@njit(cache=True)
def line_arc_poses(
    x0: float, y0: float, hdg: float, k: float, u: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`line_arc_pose` at every ``u``."""
    x, y, h = np.empty(len(u)), np.empty(len(u)), np.empty(len(u))
    c0, s0 = math.cos(hdg), math.sin(hdg)
    for i in range(len(u)):
        x[i], y[i], h[i] = line_arc_pose(x0, y0, hdg, c0, s0, k, u[i])
    return x, y, h


@njit(cache=True)
def road_pose_at(
    length: float,
    geom: np.ndarray,
    elev_s0: np.ndarray,
    elev_c: np.ndarray,
    s: float,
    t: float,
) -> tuple[float, float, float, float]:
    """(x, y, z, reference-line heading) at road ``s`` (clamped to the road for the
    reference line, not for the elevation), lateral ``t`` (m), on the road of PlanView
    arrays ``length``, ``geom``, ``elev_s0``, ``elev_c``."""
    sc = min(max(s, 0.0), length)
    g = 0
    for j in range(1, len(geom)):
        if geom[j, G_S0] <= sc:
            g = j
        else:
            break
    hdg, ch, sh = geom[g, G_HDG], geom[g, G_COS], geom[g, G_SIN]
    rx, ry, h = line_arc_pose(
        geom[g, G_X], geom[g, G_Y], hdg, ch, sh, geom[g, G_K], sc - geom[g, G_S0]
    )
    if h != hdg:  # on an arc (on a line the heading is the geometry's, cos and sin known)
        ch, sh = math.cos(h), math.sin(h)
    z = cubic_at(elev_s0, elev_c, 0, len(elev_s0), s)
    return rx - t * sh, ry + t * ch, z, h
