"""Kinematic motion of scripted actors: exact road-coordinate state advanced every step by
the storyboard's longitudinal and lateral transitions, or moved along a path.

An actor on a road holds its reference point in road coordinates (road, lane, s, t) and its
speed v along the lane; s advances by the distance travelled divided by (1 - curvature * t),
so the speed is the speed along the actor's own curve. t is the lateral position from the
reference line (left positive). World poses are computed in one batch per road from the
OpenDRIVE geometry. Off-road motion (trajectories, routes) follows a polyline in the plane.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.scenario.engine.shapes import progress
from hiyari.bridge.scenario.model.actions import Shape
from hiyari.bridge.scenario.model.entities import Entity
from hiyari.net.road.opendrive_lanes import OpenDriveMap


@dataclass
class SpeedTransition:
    """Longitudinal: speed from ``v0`` to ``target()`` with ``shape`` over ``span`` seconds
    (``by_distance``: metres travelled). ``continuous``: keeps tracking the target after."""

    v0: float
    target: Callable[[], float]
    shape: Shape
    span: float
    by_distance: bool
    continuous: bool
    t0: float
    travelled: float = 0.0
    reached: bool = False

    def speed(self, now: float, travelled: float) -> tuple[float, bool]:
        """(speed at ``now``, done) with ``travelled`` metres since the start."""
        goal = self.target()
        x = (
            1.0
            if self.span <= 0
            else (travelled if self.by_distance else now - self.t0) / self.span
        )
        if self.reached or x >= 1.0 - 1e-9:
            self.reached = True
            return goal, not self.continuous
        return self.v0 + (goal - self.v0) * progress(self.shape, x), False


@dataclass
class LateralTransition:
    """Lateral: t from ``t0`` to ``target(s)`` with ``shape`` over ``span`` seconds (or metres
    travelled); at the end the actor is on ``lane`` at ``offset``. ``continuous``: holds the
    (possibly moving) target afterwards."""

    t0: float
    target: Callable[[float], float]
    shape: Shape
    span: float
    by_distance: bool
    lane: int
    continuous: bool
    t_start: float

    def lateral(self, now: float, travelled: float, s: float) -> tuple[float, bool]:
        """(t at ``now`` and road ``s``, done)."""
        goal = self.target(s)
        x = (
            1.0
            if self.span <= 0
            else (travelled if self.by_distance else now - self.t_start) / self.span
        )
        if x >= 1.0 - 1e-9:
            return goal, not self.continuous
        return self.t0 + (goal - self.t0) * progress(self.shape, x), False


@dataclass
class PathMotion:
    """Motion along a polyline (x, y per vertex): by vertex times (``times``, s of scenario
    time) or at the actor's speed; ``headings`` (rad) per vertex or None (motion direction).
    ``stop_at_end``: the actor stands at the last vertex afterwards."""

    points: np.ndarray  # (n, 2)
    times: np.ndarray | None
    headings: np.ndarray | None
    stop_at_end: bool
    travelled: float = 0.0

    def __post_init__(self) -> None:
        seg = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        self.cum = np.concatenate([[0.0], np.cumsum(seg)])

    def advance(self, now: float, v: float, dt: float) -> tuple[float, float, float, float, bool]:
        """(x, y, heading, speed, done) at ``now`` after a step of ``dt`` at speed ``v``."""
        if self.times is not None:
            tt = self.times
            d = float(np.interp(now, tt, self.cum))
            k = int(np.clip(np.searchsorted(tt, now, side="right") - 1, 0, len(tt) - 2))
            dur = tt[k + 1] - tt[k]
            speed = (self.cum[k + 1] - self.cum[k]) / dur if dur > 0 and now < tt[-1] else 0.0
            done = now >= tt[-1] - 1e-9
        else:
            self.travelled = min(self.cum[-1], self.travelled + v * dt)
            d, speed = self.travelled, v
            done = self.travelled >= self.cum[-1] - 1e-9
        x = float(np.interp(d, self.cum, self.points[:, 0]))
        y = float(np.interp(d, self.cum, self.points[:, 1]))
        k = int(np.clip(np.searchsorted(self.cum, d, side="right") - 1, 0, len(self.cum) - 2))
        if self.headings is not None:
            frac = (d - self.cum[k]) / max(self.cum[k + 1] - self.cum[k], 1e-12)
            h0, h1 = self.headings[k], self.headings[k + 1]
            h = h0 + frac * math.remainder(h1 - h0, 2 * math.pi)
        else:
            seg = self.points[k + 1] - self.points[k]
            h = math.atan2(seg[1], seg[0])
        return x, y, h, speed, done


@dataclass
class Actor:
    """A scripted actor's kinematic state (reference point, road coordinates or free pose)."""

    name: str
    entity: Entity
    road: str = ""
    lane: int = 0
    s: float = 0.0
    t: float = 0.0
    v: float = 0.0
    accel: float = 0.0
    v_lat: float = 0.0  # dt/dt, m/s (road t direction)
    h_rel: float = 0.0  # heading relative to the lane's driving direction, rad
    free: bool = False  # moving in the plane (path), not in road coordinates
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    h: float = 0.0
    long: SpeedTransition | None = None
    lat: LateralTransition | None = None
    path: PathMotion | None = None
    long_travelled: float = 0.0
    lat_travelled: float = 0.0
    inserted: bool = False

    def centre(self) -> tuple[float, float]:
        """Bounding-box centre in network x, y (m)."""
        cx, cy, _ = self.entity.centre
        c, s = math.cos(self.h), math.sin(self.h)
        return self.x + cx * c - cy * s, self.y + cx * s + cy * c


def forward(odr: OpenDriveMap, road: str, lane: int) -> float:
    """+1 when ``lane`` of ``road`` drives towards increasing s, else -1."""
    return 1.0 if odr.road(road).drives_forward(lane) else -1.0


def curvature(odr: OpenDriveMap, road: str, s: np.ndarray) -> np.ndarray:
    """Reference-line curvature at road ``s`` (1/m), from the heading 0.5 m either side."""
    rd = odr.road(road)
    lo, hi = np.clip(s - 0.5, 0, rd.length), np.clip(s + 0.5, 0, rd.length)
    h_lo, h_hi = rd.reference(lo)[2], rd.reference(hi)[2]
    return np.where(hi > lo, (h_hi - h_lo) / np.maximum(hi - lo, 1e-9), 0.0)


def advance_road_actors(odr: OpenDriveMap, actors: list[Actor], now: float, dt: float) -> None:
    """Advance actors in road coordinates by one step to scenario time ``now``; batch their
    world poses per road."""
    by_road: dict[str, list[Actor]] = {}
    for a in actors:
        by_road.setdefault(a.road, []).append(a)
    for road, group in by_road.items():
        s = np.array([a.s for a in group])
        t = np.array([a.t for a in group])
        kappa = curvature(odr, road, s)
        for k, a in enumerate(group):
            v_old = a.v
            if a.long is not None:
                a.v, done = a.long.speed(now, a.long_travelled + v_old * dt)
                if done:
                    a.long = None
            a.accel = (a.v - v_old) / dt
            ds_path = 0.5 * (v_old + a.v) * dt
            a.long_travelled += ds_path
            a.lat_travelled += ds_path
            direction = forward(odr, road, a.lane)
            a.s += direction * ds_path / max(1e-3, 1.0 - kappa[k] * t[k])
            if a.lat is not None:
                t_new, done = a.lat.lateral(now, a.lat_travelled, a.s)
                a.v_lat = (t_new - a.t) / dt
                a.t = t_new
                if done:
                    a.lane, a.lat = a.lat.lane, None
            else:
                a.v_lat = 0.0
        place_on_road(odr, road, group)


def place_on_road(odr: OpenDriveMap, road: str, group: list[Actor]) -> None:
    """World pose (x, y, z, heading) of actors from their road coordinates."""
    s = np.array([a.s for a in group])
    t = np.array([a.t for a in group])
    x, y, z, h_ref = odr.road_pose(road, s, t)
    for k, a in enumerate(group):
        direction = forward(odr, road, a.lane)
        base = h_ref[k] + (0.0 if direction > 0 else math.pi)
        slip = math.atan2(direction * a.v_lat, a.v) if abs(a.v) > 1e-6 else 0.0
        a.x, a.y, a.z = float(x[k]), float(y[k]), float(z[k])
        a.h = math.remainder(base + slip + a.h_rel, 2 * math.pi)
