"""The ego's corridor follows its lane: threat assessment in path coordinates.

A straight-line prediction on a curved road puts a car in the adjacent lane into the ego's
path: on the ALKS side-vehicle road (4_1_3) the stack computed 2.4-2.7 s to a car whose true
TTC was infinite, and raised AEB warnings. Instead, tracks are taken into the frame of the
ego's predicted path, an arc of the road's curvature through the ego: ``s`` along the arc, ``d``
to its left (Frenet coordinates), velocities as ``ds/dt`` and ``dd/dt``. In that frame the
ego drives straight along ``s`` and a car keeping its lane keeps its ``d``, so the slab test
of hiyari.kinematics.footprint_entry_time applies unchanged (the one TTC kernel).

The road's curvature is read from the ego's own path: the ego follows its lane, so its
heading turns with the road, and the heading change over the last ``CorridorConfig.window``
metres travelled divided by that distance is the lane's curvature, averaged over the window
(a lane change adds a brief S of opposite curvatures that the window mostly cancels).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from hiyari.kinematics import Pose, wrap_angle


@dataclass(frozen=True)
class CorridorConfig:
    """How the corridor's curvature is estimated (SI)."""

    #: m of the ego's own path over which the curvature is averaged: long enough to smooth
    #: the heading steps of a lane polyline (SUMO's lanes are sampled every few metres), short
    #: enough that the corridor bends within a second of entering a curve at 60 km/h.
    window: float = 20.0
    #: 1/m: below this the corridor is straight (a 10 km radius bends less than 5 cm in 30 m).
    straight_curvature: float = 1e-4
    #: m: the distance travelled before a curvature is estimated (until then: straight).
    min_travel: float = 5.0
    #: where a vehicle's rear axle is, as a share of its length from its rear end: a vehicle
    #: following its lane heads along the lane's tangent there (its front swings out). 0.2:
    #: about 1 m of rear overhang on a 4.8 m car; 3.75 m on an 18.75 m truck, whose axle the
    #: ALKS 4_1_3 runs put 3.4 m from its rear (its heading there is the lane's).
    rear_axle: float = 0.2


class PathCurvature:
    """The curvature (1/m, positive to the left) of the ego's recent path (see module)."""

    def __init__(self, config: CorridorConfig | None = None) -> None:
        self.config = config or CorridorConfig()
        self._trail: deque[tuple[float, float]] = deque()  # (distance travelled m, heading)
        self._xy: tuple[float, float] | None = None
        self._travelled = 0.0
        self._turned = 0.0  # heading unwrapped along the path, rad

    def update(self, ego: Pose) -> float:
        """Take the ego's pose of this step; the curvature of its last ``window`` metres."""
        c = self.config
        if self._xy is None:
            self._trail.append((0.0, ego.heading))
            self._turned = ego.heading
        else:
            step = math.hypot(ego.x - self._xy[0], ego.y - self._xy[1])
            if step > 0.0:
                self._travelled += step
                self._turned += float(wrap_angle(ego.heading - self._last_heading))
                self._trail.append((self._travelled, self._turned))
        self._xy, self._last_heading = (ego.x, ego.y), ego.heading
        while len(self._trail) > 2 and self._travelled - self._trail[1][0] >= c.window:
            self._trail.popleft()
        s0, h0 = self._trail[0]
        span = self._travelled - s0
        if span < c.min_travel:
            return 0.0
        kappa = (self._turned - h0) / span
        return kappa if abs(kappa) >= c.straight_curvature else 0.0


def to_corridor(
    position: np.ndarray,
    velocity: np.ndarray,
    heading: np.ndarray,
    ego_speed: float,
    curvature: float,
    aligned: np.ndarray | None = None,
    length: np.ndarray | None = None,
    rear_axle: float = CorridorConfig.rear_axle,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Objects in the ego frame -> the corridor frame of an arc of ``curvature`` (1/m) through
    the ego: positions (N, 2) m -> (s, d); velocities relative to the ego (N, 2) m/s (the ego
    moving at ``ego_speed`` along x) -> (ds/dt, dd/dt) relative to the ego moving along s;
    headings (N,) rad relative to the ego -> relative to the arc's direction where the object
    is; objects flagged ``aligned`` (N,) (standing: no heading of their own) stay aligned,
    now with the arc. A zero curvature leaves everything as it is.

    Velocities and headings are taken relative to the arc's direction at each object's rear
    axle, ``rear_axle`` of its ``length`` (N,) m from its rear end along its heading (None:
    at its centre): a vehicle's heading is the lane's tangent at its rear axle, not at the
    middle of its box. On ALKS 4_1_3 the 18.75 m truck beside the ego heads along the lane
    about 6 m behind its box centre; taken at the centre, its velocity seemed to cross into
    the ego's corridor at 0.2 m/s."""
    p = np.asarray(position, float)
    v = np.asarray(velocity, float)
    h = np.asarray(heading, float)
    k = float(curvature)
    if k == 0.0 or not len(p):
        return p, v, h
    x, y = p[:, 0], p[:, 1]
    psi_c = np.arctan2(k * x, 1.0 - k * y)  # the arc's direction at the object's projection
    s = psi_c / k
    d = (1.0 - np.hypot(k * x, 1.0 - k * y)) / k
    psi = psi_c
    if length is not None:
        back = (0.5 - rear_axle) * np.nan_to_num(np.asarray(length, float))
        xr, yr = x - back * np.cos(h), y - back * np.sin(h)
        psi = np.arctan2(k * xr, 1.0 - k * yr)
    vx, vy = v[:, 0] + ego_speed, v[:, 1]  # over ground, on the ego's axes
    c, sn = np.cos(psi), np.sin(psi)
    along = (vx * c + vy * sn) / np.maximum(1.0 - k * d, 1e-6)
    across = -vx * sn + vy * c
    return (
        np.stack([s, d], axis=1),
        np.stack([along - ego_speed, across], axis=1),
        np.where(aligned, 0.0, wrap_angle(h - psi)) if aligned is not None else wrap_angle(h - psi),
    )
