"""Point in area (the carriageway) without GEOS for the points it can decide exactly.

The SCT metrics ask, for thousands of predicted pedestrian positions per step, whether each
lies inside the carriageway (shapely.contains_xy: the interior, the boundary excluded). For a
valid polygon or multipolygon that is the parity of a ray's crossings with its rings, exactly
as GEOS's point locator counts them. Here the parity is counted in a compiled loop with every
orientation sign decided by Shewchuk's error bound for orient2d: a point whose sign the bound
cannot guarantee (on an edge, a vertex, or within rounding of one) is left undecided and asked
of shapely. So every answer is GEOS's, bit for bit (tests/unit/risk/test_sct_contact_kernel.py), and
GEOS is called only for points on or within ~1e-15 m of the boundary.

Frames and units: network coordinates in metres.
"""

from __future__ import annotations

import numpy as np
import shapely

from hiyari.jit import njit

# Shewchuk's ccwerrboundA, (3 + 16 eps) eps with eps = 2^-53: |det| above it times the
# permanent means the floating-point orient2d has the exact sign
_CCW_ERROR = (3.0 + 16.0 * 2.0**-53) * 2.0**-53


@njit(cache=True)
def _side(px: float, py: float, x1: float, y1: float, x2: float, y2: float) -> int:
    """For a point in the bounding box of edge (x1, y1) -> (x2, y2): 1 left of it, -1 right,
    0 undecided (on it, or too near for the floating-point orientation to be sure)."""
    left = (x1 - px) * (y2 - py)
    right = (y1 - py) * (x2 - px)
    det = left - right
    if abs(det) <= _CCW_ERROR * (abs(left) + abs(right)):
        return 0
    return 1 if det > 0.0 else -1


@njit(cache=True)
def _locate_rings(px: float, py: float, ring_xy: np.ndarray, ring_start: np.ndarray) -> int:
    """locate_xy of one point over every edge of the rings."""
    crossings = 0
    for r in range(len(ring_start) - 1):
        for e in range(ring_start[r], ring_start[r + 1] - 1):
            x1, y1 = ring_xy[e, 0], ring_xy[e, 1]
            x2, y2 = ring_xy[e + 1, 0], ring_xy[e + 1, 1]
            if (y1 > py and y2 > py) or (y1 < py and y2 < py):
                continue  # wholly above or below the point's row
            straddles = (y1 > py) != (y2 > py)  # half-open: one end above, one not
            if px < min(x1, x2):
                crossings += straddles  # wholly right of the point: the ray hits it
                continue
            if px > max(x1, x2):
                continue
            side = _side(px, py, x1, y1, x2, y2)
            if side == 0:
                return -1
            if straddles and (side > 0) == (y2 > y1):
                crossings += 1  # left of an upward edge or right of a downward one
    return crossings & 1


@njit(cache=True)
def locate_xy(
    points: np.ndarray,
    ring_xy: np.ndarray,
    ring_start: np.ndarray,
    slab_y: np.ndarray,
    slab_start: np.ndarray,
    slab_edges: np.ndarray,
) -> np.ndarray:
    """(n,) int8 per point (``points`` (n, 2) m): 1 inside the area bounded by the closed
    rings (``ring_xy`` (E, 2), ring r's vertices ``ring_start[r]`` .. ``ring_start[r+1] -
    1``, first = last), 0 outside, -1 undecided (on the boundary or within rounding of it).

    A point strictly between two consecutive vertex ordinates ``slab_y`` meets only the
    edges spanning that slab (``slab_edges[slab_start[s]:slab_start[s + 1]]``, indices into
    ``ring_xy`` of each edge's first vertex); a point at a vertex ordinate is counted over
    every edge. A point equal to the one before takes its answer (tracks of pedestrians
    standing still, or at speed factor 0, repeat one point)."""
    out = np.empty(len(points), np.int8)
    top = len(slab_y) - 1
    for i in range(len(points)):
        px, py = points[i, 0], points[i, 1]
        if i and px == points[i - 1, 0] and py == points[i - 1, 1]:
            out[i] = out[i - 1]
            continue
        if not slab_y[0] <= py <= slab_y[top]:
            out[i] = 0  # above or below every edge
            continue
        s = np.searchsorted(slab_y, py)
        if slab_y[s] == py:
            out[i] = _locate_rings(px, py, ring_xy, ring_start)
            continue
        crossings = 0
        for j in range(slab_start[s - 1], slab_start[s]):
            e = slab_edges[j]
            x1, y1 = ring_xy[e, 0], ring_xy[e, 1]
            x2, y2 = ring_xy[e + 1, 0], ring_xy[e + 1, 1]
            if px < min(x1, x2):
                crossings += 1  # spans the row, wholly right of the point
                continue
            if px > max(x1, x2):
                continue
            side = _side(px, py, x1, y1, x2, y2)
            if side == 0:
                crossings = -1
                break
            if (side > 0) == (y2 > y1):
                crossings += 1
        out[i] = -1 if crossings < 0 else crossings & 1
    return out


class AreaTest:
    """shapely.contains_xy on one area, counted in locate_xy where the area is a valid
    (multi)polygon; GEOS answers the undecided points (and everything for other areas)."""

    def __init__(self, area: shapely.Geometry) -> None:
        self.area = area
        self._rings: tuple[np.ndarray, ...] | None = None
        if shapely.get_type_id(area) in (3, 6) and not area.is_empty and shapely.is_valid(area):
            rings = shapely.get_rings(shapely.get_parts(area))
            coords = [shapely.get_coordinates(r) for r in rings]
            start = np.cumsum([0] + [len(c) for c in coords])
            xy = np.ascontiguousarray(np.concatenate(coords))
            self._rings = (xy, start.astype(np.int64), *_slabs(xy, start))

    @property
    def rings(self) -> tuple[np.ndarray, ...] | None:
        """locate_xy's ring and slab arguments, or None when it cannot count this area."""
        return self._rings

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(...) bool: the ``points`` (..., 2) m strictly inside the area."""
        if self._rings is None:
            return shapely.contains_xy(self.area, points[..., 0], points[..., 1])
        flat = np.ascontiguousarray(points, float).reshape(-1, 2)
        where = locate_xy(flat, *self._rings)
        out = where == 1
        ask = np.flatnonzero(where < 0)
        if len(ask):
            out[ask] = shapely.contains_xy(self.area, flat[ask, 0], flat[ask, 1])
        return out.reshape(points.shape[:-1])


def _slabs(xy: np.ndarray, start: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rings' vertex ordinates (sorted, distinct) and, per slab between two of them, the
    edges (index of their first vertex) spanning it, in CSR form."""
    first = np.concatenate(
        [np.arange(a, b - 1) for a, b in zip(start[:-1], start[1:], strict=True)]
    )
    y1, y2 = xy[first, 1], xy[first + 1, 1]
    low, high = np.minimum(y1, y2), np.maximum(y1, y2)
    slab_y = np.unique(xy[:, 1])
    spans = (low[None, :] <= slab_y[:-1, None]) & (high[None, :] >= slab_y[1:, None])  # (S, E)
    slab_start = np.concatenate([[0], np.cumsum(spans.sum(axis=1))]).astype(np.int64)
    return slab_y, slab_start, first[np.nonzero(spans)[1]].astype(np.int64)
