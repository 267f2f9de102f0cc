"""Kinematic motion of scripted actors: exact road-coordinate state advanced every step by
the storyboard's longitudinal and lateral transitions, or moved along a path.

An actor on a road holds its reference point in road coordinates (road, lane, s, t) and its
speed v along the lane; s advances by the distance travelled divided by (1 - curvature * t),
so the speed is the speed along the actor's own curve. t is the lateral position from the
reference line (left positive). The state of all actors lives in one ActorTable (arrays, a
row per entity; an Actor's attributes are views of its row), so a step advances every actor on
a road in one numpy pass and only the running transitions one by one; world poses are computed
in one batch per road from the OpenDRIVE geometry. Off-road motion (trajectories, routes)
follows a polyline in the plane.
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


class ActorTable:
    """Every actor's kinematic state as arrays, one row per entity (scenario order), so that a
    step advances, places and commands all scripted actors in a few numpy passes. Road ids are
    kept as a list and as codes (index into ``road_ids``); ``direction`` (+1 / -1 along s) is
    recomputed for rows whose road or lane changed (``stale``)."""

    FLOATS = ("s", "t", "v", "accel", "v_lat", "h_rel", "x", "y", "z", "h",
              "long_travelled", "lat_travelled")  # fmt: skip

    def __init__(self, n: int) -> None:
        for name in self.FLOATS:
            setattr(self, name, np.zeros(n))
        self.lane = np.zeros(n, dtype=np.int64)
        self.free = np.zeros(n, dtype=bool)
        self.inserted = np.zeros(n, dtype=bool)
        self.has_long = np.zeros(n, dtype=bool)
        self.has_lat = np.zeros(n, dtype=bool)
        self.road: list[str] = [""] * n
        self.road_ids: list[str] = []
        self.road_code = np.full(n, -1, dtype=np.intp)
        self.direction = np.ones(n)
        self.stale = np.zeros(n, dtype=bool)
        #: Counts installs and removals of transitions and paths: the running actions can
        #: only have finished when it moved.
        self.motion_version = 0

    def set_road(self, k: int, road: str) -> None:
        """Row ``k`` is on ``road`` ('' for none)."""
        self.road[k] = road
        if road and road not in self.road_ids:
            self.road_ids.append(road)
        self.road_code[k] = self.road_ids.index(road) if road else -1
        self.stale[k] = True

    def refresh(self, odr: OpenDriveMap) -> None:
        """Driving directions of rows whose road or lane changed."""
        if not self.stale.any():
            return
        for k in np.flatnonzero(self.stale).tolist():
            road = self.road[k]
            self.direction[k] = forward(odr, road, int(self.lane[k])) if road else 1.0
        self.stale[:] = False


class _Column:
    """An Actor attribute stored in its row of the ActorTable column of the same name."""

    def __init__(self, cast: type, marks_stale: bool = False) -> None:
        self.cast, self.marks_stale = cast, marks_stale

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, obj: Actor | None, owner: type | None = None) -> object:
        if obj is None:
            return self
        return self.cast(getattr(obj.table, self.name)[obj.k])

    def __set__(self, obj: Actor, value: object) -> None:
        getattr(obj.table, self.name)[obj.k] = value
        if self.marks_stale:
            obj.table.stale[obj.k] = True


class Actor:
    """A scripted actor: its kinematic state (reference point in road coordinates (road, lane,
    s, t) or as a free pose x, y, z, h; speed v, acceleration, lateral speed v_lat (road t
    direction), heading relative to the lane h_rel) lives in row ``k`` of the ActorTable; its
    running transitions and path are attributes."""

    s = _Column(float)
    t = _Column(float)
    v = _Column(float)
    accel = _Column(float)
    v_lat = _Column(float)
    h_rel = _Column(float)
    x = _Column(float)
    y = _Column(float)
    z = _Column(float)
    h = _Column(float)
    long_travelled = _Column(float)
    lat_travelled = _Column(float)
    lane = _Column(int, marks_stale=True)
    free = _Column(bool)
    inserted = _Column(bool)

    def __init__(self, name: str, entity: Entity, table: ActorTable, k: int) -> None:
        self.name, self.entity, self.table, self.k = name, entity, table, k
        self._long: SpeedTransition | None = None
        self._lat: LateralTransition | None = None
        self._path: PathMotion | None = None

    @property
    def road(self) -> str:
        """OpenDRIVE road id ('' when off every road)."""
        return self.table.road[self.k]

    @road.setter
    def road(self, value: str) -> None:
        self.table.set_road(self.k, value)

    @property
    def long(self) -> SpeedTransition | None:
        """The running longitudinal transition."""
        return self._long

    @long.setter
    def long(self, value: SpeedTransition | None) -> None:
        self._long = value
        self.table.has_long[self.k] = value is not None
        self.table.motion_version += 1

    @property
    def lat(self) -> LateralTransition | None:
        """The running lateral transition."""
        return self._lat

    @lat.setter
    def lat(self, value: LateralTransition | None) -> None:
        self._lat = value
        self.table.has_lat[self.k] = value is not None
        self.table.motion_version += 1

    @property
    def path(self) -> PathMotion | None:
        """The path being followed."""
        return self._path

    @path.setter
    def path(self, value: PathMotion | None) -> None:
        self._path = value
        self.table.motion_version += 1

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


def by_road(table: ActorTable, rows: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """``rows`` grouped by their road: (road id, rows on it)."""
    codes = table.road_code[rows]
    first = codes[0] if len(codes) else -1
    if len(codes) and (codes == first).all():
        return [(table.road_ids[first], rows)] if first >= 0 else []
    return [(table.road_ids[c], rows[codes == c]) for c in np.unique(codes).tolist() if c >= 0]


def advance_road_actors(
    odr: OpenDriveMap, actors: list[Actor], rows: np.ndarray, now: float, dt: float
) -> None:
    """Advance the road actors in table ``rows`` (indices into ``actors``, which share one
    table) by one step to scenario time ``now``: all rows of a road in one numpy pass, the
    running transitions one by one."""
    if not len(rows):
        return
    table = actors[0].table
    table.refresh(odr)
    for road, r in by_road(table, rows):
        s, t, v_old = table.s[r], table.t[r], table.v[r]
        v_new = v_old.copy()
        ramp = np.full(len(r), dt)  # s of this step spent ramping from v_old to v_new
        for j in np.flatnonzero(table.has_long[r]).tolist():
            a = actors[r[j]]
            v_new[j], done = a.long.speed(now, a.long_travelled + v_old[j] * dt)
            if done:
                if not a.long.by_distance:  # ended within the step: at v_new since then
                    ramp[j] = min(dt, max(0.0, a.long.t0 + a.long.span - (now - dt)))
                a.long = None
        ds_path = 0.5 * (v_old + v_new) * ramp + v_new * (dt - ramp)
        kappa = curvature(odr, road, s)
        table.s[r] = s + table.direction[r] * ds_path / np.maximum(1e-3, 1.0 - kappa * t)
        table.v[r] = v_new
        table.accel[r] = (v_new - v_old) / dt
        table.long_travelled[r] += ds_path
        table.lat_travelled[r] += ds_path
        table.v_lat[r] = 0.0
        for k in r[table.has_lat[r]].tolist():
            a = actors[k]
            t_new, done = a.lat.lateral(now, a.lat_travelled, a.s)
            a.v_lat = (t_new - a.t) / dt
            a.t = t_new
            if done:
                a.lane, a.lat = a.lat.lane, None
        place_on_road(odr, road, table, r)


def place_on_road(odr: OpenDriveMap, road: str, table: ActorTable, rows: np.ndarray) -> None:
    """World pose (x, y, z, heading) of table ``rows`` on ``road`` from their road
    coordinates."""
    table.refresh(odr)
    x, y, z, h_ref = odr.road_pose(road, table.s[rows], table.t[rows])
    direction = table.direction[rows]
    v = table.v[rows]
    slip = np.where(np.abs(v) > 1e-6, np.arctan2(direction * table.v_lat[rows], v), 0.0)
    h = h_ref + np.where(direction > 0, 0.0, np.pi) + slip + table.h_rel[rows]
    table.x[rows], table.y[rows], table.z[rows] = x, y, z
    table.h[rows] = np.remainder(h + np.pi, 2 * np.pi) - np.pi


def place_actor(odr: OpenDriveMap, a: Actor) -> None:
    """World pose of one road actor from its road coordinates."""
    place_on_road(odr, a.road, a.table, np.array([a.k]))
