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
    return 1.0 if odr.roads[road].drives_forward(lane) else -1.0


def curvature(odr: OpenDriveMap, road: str, s: np.ndarray) -> np.ndarray:
    """Reference-line curvature at road ``s`` (1/m), from the heading 0.5 m either side."""
    rd = odr.road(road)
    if all(g.kind == "line" for g in rd.geometries):
        return np.zeros_like(s)
    lo, hi = np.clip(s - 0.5, 0, rd.length), np.clip(s + 0.5, 0, rd.length)
    h_lo, h_hi = rd.reference(lo)[2], rd.reference(hi)[2]
    return np.where(hi > lo, (h_hi - h_lo) / np.maximum(hi - lo, 1e-9), 0.0)


def advance_road_actors(odr: OpenDriveMap, actors: list[Actor], now: float, dt: float) -> None:
    """Advance actors in road coordinates by one step to scenario time ``now``; their world
    poses are computed in one batch per road."""
    by_road: dict[str, list[Actor]] = {}
    for a in actors:
        by_road.setdefault(a.road, []).append(a)
    for road, group in by_road.items():
        n = len(group)
        s = np.fromiter((a.s for a in group), float, n)
        t = np.fromiter((a.t for a in group), float, n)
        v_old = np.fromiter((a.v for a in group), float, n)
        v_new = v_old.copy()
        for k, a in enumerate(group):
            if a.long is not None:
                v_new[k], done = a.long.speed(now, a.long_travelled + v_old[k] * dt)
                if done:
                    a.long = None
        direction = np.fromiter((forward(odr, road, a.lane) for a in group), float, n)
        ds_path = 0.5 * (v_old + v_new) * dt
        s_new = s + direction * ds_path / np.maximum(1e-3, 1.0 - curvature(odr, road, s) * t)
        accel = (v_new - v_old) / dt
        for k, a in enumerate(group):
            a.s, a.v, a.accel = float(s_new[k]), float(v_new[k]), float(accel[k])
            a.long_travelled += float(ds_path[k])
            a.lat_travelled += float(ds_path[k])
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
    n = len(group)
    s = np.fromiter((a.s for a in group), float, n)
    t = np.fromiter((a.t for a in group), float, n)
    x, y, z, h_ref = odr.road_pose(road, s, t)
    direction = np.fromiter((forward(odr, road, a.lane) for a in group), float, n)
    v = np.fromiter((a.v for a in group), float, n)
    v_lat = np.fromiter((a.v_lat for a in group), float, n)
    h_rel = np.fromiter((a.h_rel for a in group), float, n)
    slip = np.where(np.abs(v) > 1e-6, np.arctan2(direction * v_lat, v), 0.0)
    h = h_ref + np.where(direction > 0, 0.0, np.pi) + slip + h_rel
    h = np.remainder(h + np.pi, 2 * np.pi) - np.pi
    for a, xk, yk, zk, hk in zip(
        group, x.tolist(), y.tolist(), z.tolist(), h.tolist(), strict=True
    ):
        a.x, a.y, a.z, a.h = xk, yk, zk, hk
