"""Kinematic motion of scripted actors: exact road-coordinate state advanced every step by
the storyboard's longitudinal and lateral transitions, or moved along a path.

An actor on a road holds its reference point in road coordinates (road, lane, s, t) and its
speed v along the lane; s advances by the distance travelled divided by (1 - curvature * t),
so the speed is the speed along the actor's own curve. t is the lateral position from the
reference line (left positive). The state of all actors lives in one ActorTable (arrays, a
column per entity; an Actor's attributes read and write its column), and so do the running
transitions' parameters: a step advances every actor on a road, its transitions included, in
compiled passes (``motion_kernel``), and places it in the world from the OpenDRIVE geometry
(compiled for lines and arcs, else the numpy road pose). Goals that follow another entity are
read in Python before each pass, while such a transition runs. Off-road motion (trajectories,
routes) follows a polyline in the plane.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.openscenario.engine.kernels import command_kernel as CK
from hiyari.bridge.openscenario.engine.kernels import motion_kernel as MK
from hiyari.bridge.openscenario.engine.kernels.shapes import SHAPE_CODE
from hiyari.bridge.openscenario.engine.kernels.tables import (
    ActorArrays,
    CommandArrays,
    LaneArrays,
    RoadArrays,
)
from hiyari.bridge.openscenario.engine.paths.sampled import SampledPath
from hiyari.bridge.openscenario.model.actions import Shape
from hiyari.bridge.openscenario.model.entities import Entity
from hiyari.net.road.lane_profile import LaneProfile, lane_profile
from hiyari.net.road.opendrive_lanes import OpenDriveMap
from hiyari.net.road.plan_view import PlanView


@dataclass(eq=False)
class SpeedTransition:
    """Longitudinal: speed from ``v0`` to ``goal`` (m/s) with ``shape`` over ``span`` seconds
    (``by_distance``: metres travelled) from scenario time ``t0``. ``target``: for a goal
    that follows another entity, returns it each step. ``continuous``: keeps tracking the
    goal after."""

    v0: float
    goal: float
    target: Callable[[], float] | None
    shape: Shape
    span: float
    by_distance: bool
    continuous: bool
    t0: float

    def row(self) -> list[float]:
        """Parameter row for the motion kernel (columns ``motion_kernel.L_*``)."""
        return [self.v0, self.goal, SHAPE_CODE[self.shape], self.span, self.by_distance,
                self.continuous, self.t0, 0.0]  # fmt: skip


@dataclass(eq=False)
class LateralTransition:
    """Lateral: t from ``t0`` to the centre line of ``lane`` of road ``road`` plus ``offset``
    (m) with ``shape`` over ``span`` seconds (or metres travelled) from scenario time
    ``t_start``; at the end the actor is on ``lane``. ``offset_of``: for an offset that follows
    another entity, returns it each step. ``continuous``: holds the (possibly moving) target
    afterwards."""

    t0: float
    road: str
    lane: int
    offset: float
    offset_of: Callable[[], float] | None
    shape: Shape
    span: float
    by_distance: bool
    continuous: bool
    t_start: float

    def row(self, road_code: int) -> list[float]:
        """Parameter row for the motion kernel (columns ``motion_kernel.T_*``)."""
        return [self.t0, self.offset, SHAPE_CODE[self.shape], self.span, self.by_distance,
                self.continuous, self.t_start, self.lane, road_code]  # fmt: skip


@dataclass(eq=False)
class PathMotion:
    """Motion along a sampled path: by scenario times (``times``, s, one per path point: the
    actor is where the path says when) or by the distance the actor's speed covers (None).
    ``travelled``: m along the path now; ``reverse``: the actor backs along it (it faces
    against the direction of travel); ``stop_at_end``: it stands at the end afterwards (else
    it goes on at its speed, ``beyond`` m past the end in the step the path ended)."""

    path: SampledPath
    times: np.ndarray | None
    stop_at_end: bool = False
    travelled: float = 0.0
    reverse: bool = False
    beyond: float = 0.0

    def pose(self) -> tuple[float, float, float]:
        """(x, y, heading) where the actor is now on the path: the path's heading there, or,
        backing, the opposite of its direction of travel."""
        x, y, h = self.path.pose(self.travelled)
        if self.reverse:
            h = math.remainder(self.path.direction(self.travelled) + math.pi, 2 * math.pi)
        return x, y, h

    def start(self, now: float) -> tuple[float, float, float]:
        """(x, y, heading) at the start: at scenario time ``now`` on a timed path."""
        if self.times is not None:
            self.travelled = float(np.interp(now, self.times, self.path.s))
        return self.pose()

    def advance(self, now: float, ds: float) -> tuple[float, float, float, float | None, bool]:
        """(x, y, heading, speed or None, done) at ``now``, after moving ``ds`` m when untimed
        (the speed is then the actor's own: None). A timed path's speed is its segment's;
        past the end, the last segment's: the actor keeps the speed the trajectory gave it
        (OpenSCENARIO ends the action there, it does not stop the entity). ``beyond``: the
        distance the step would have gone past the end."""
        speed = None
        if self.times is not None:
            tt, s = self.times, self.path.s
            self.travelled = float(np.interp(now, tt, s))
            k = int(np.clip(np.searchsorted(tt, now, side="right") - 1, 0, len(tt) - 2))
            while k > 0 and tt[k + 1] - tt[k] <= 0:  # a repeated last time: the one before
                k -= 1
            dur = tt[k + 1] - tt[k]
            speed = (s[k + 1] - s[k]) / dur if dur > 0 else 0.0
            done = now >= tt[-1] - 1e-9
            self.beyond = max(0.0, now - tt[-1]) * speed
        else:
            self.beyond = max(0.0, self.travelled + abs(ds) - self.path.length)
            self.travelled = min(self.path.length, self.travelled + abs(ds))
            done = self.travelled >= self.path.length - 1e-9
        x, y, h = self.pose()
        return x, y, h, speed, done


class ActorTable:
    """Every actor's kinematic state and running transitions as arrays, one entry per entity
    (scenario order), so that a step advances, places and commands all scripted actors in a
    few compiled passes. Road ids are kept as a list and as codes (index into ``road_ids``);
    ``direction`` (+1 / -1 along s) is recomputed for rows whose road or lane changed
    (``stale``)."""

    FLOATS = MK.STATE

    def __init__(self, n: int) -> None:
        #: The float columns as one matrix (row i: column FLOATS[i]); the attributes of the
        #: same names are views of its rows.
        self.state = np.zeros((len(self.FLOATS), n))
        for i, name in enumerate(self.FLOATS):
            setattr(self, name, self.state[i])
        self.lane = np.zeros(n, dtype=np.int64)
        self.free = np.zeros(n, dtype=bool)
        self.inserted = np.zeros(n, dtype=bool)
        #: Rows driving against their lane's direction (facing the other way on it).
        self.against = np.zeros(n, dtype=bool)
        self.has_long = np.zeros(n, dtype=bool)
        self.has_lat = np.zeros(n, dtype=bool)
        self.n_lat = 0  # rows with a running lateral transition
        self.road: list[str] = [""] * n
        self.road_ids: list[str] = []
        self.road_code = np.full(n, -1, dtype=np.intp)
        self.direction = np.ones(n)
        self.stale = np.zeros(n, dtype=bool)
        #: Stale rows whose lane alone changed (a lane change on their road): they keep their
        #: direction of travel, and drive against a lane of the other driving direction.
        self.keep = np.zeros(n, dtype=bool)
        self.any_stale = False
        self.long_par = np.zeros((n, 8))  # running transitions' parameters (motion_kernel)
        self.lat_par = np.zeros((n, 9))
        self.long_done = np.zeros(n, dtype=bool)
        self.lat_done = np.zeros(n, dtype=bool)
        self.kappa = np.zeros(n)  # reference-line curvature at s before the step, 1/m
        #: The latest ``groups`` all on straight roads, their rows' kappa set to 0.
        self.straight_groups: list[tuple[str, np.ndarray]] | None = None
        #: Goals / offsets that follow another entity, by row: refreshed every step.
        self.long_targets: dict[int, Callable[[], float]] = {}
        self.lat_offsets: dict[int, Callable[[], float]] = {}
        self._profile: LaneProfile | None = None
        self._lanes: tuple[LaneProfile, LaneArrays] | None = None  # see lanes
        #: Counts road changes of rows: the grouping of rows by road holds until it moves.
        self.road_version = 0
        self._groups: tuple[np.ndarray, int, list[tuple[str, np.ndarray]]] | None = None
        #: Counts installs and removals of transitions and paths: the running actions can
        #: only have finished when it moved.
        self.motion_version = 0
        self._pass: tuple[tuple, tuple] | None = None  # see pass_args
        #: The arrays above as one table for the compiled passes (built once: the arrays are
        #: only ever updated in place; passed as ``tuple(arrays)``, see kernels.tables).
        self.arrays = ActorArrays(
            self.state, self.direction, self.kappa, self.road_code, self.lane, self.free,
            self.has_long, self.long_par, self.long_done, self.has_lat, self.lat_par,
            self.lat_done,
        )  # fmt: skip

    def set_road(self, k: int, road: str) -> None:
        """Row ``k`` is on ``road`` ('' for none)."""
        self.road[k] = road
        self.road_code[k] = self.code_of(road) if road else -1
        self.mark_stale(k)
        self.road_version += 1

    def code_of(self, road: str) -> int:
        """Index of ``road`` in ``road_ids`` (added when new)."""
        if road not in self.road_ids:
            self.road_ids.append(road)
        return self.road_ids.index(road)

    def groups(self, rows: np.ndarray) -> list[tuple[str, np.ndarray]]:
        """``by_road`` of ``rows``, kept while ``rows`` is the same array and no road changed."""
        g = self._groups
        if g is None or g[0] is not rows or g[1] != self.road_version:
            self._groups = g = (rows, self.road_version, by_road(self, rows))
        return g[2]

    def lane_profile(self, odr: OpenDriveMap) -> LaneProfile:
        """The LaneProfile of the roads in ``road_ids`` (in that order)."""
        if self._profile is None or len(self._profile.sec_first) != len(self.road_ids):
            self._profile = lane_profile([odr.road(r) for r in self.road_ids])
        return self._profile

    def lanes(self, odr: OpenDriveMap) -> LaneArrays:
        """The arrays of :meth:`lane_profile`, kept while the profile is the same."""
        prof = self.lane_profile(odr)
        if self._lanes is None or self._lanes[0] is not prof:
            self._lanes = (prof, LaneArrays(*prof.arrays()))
        return self._lanes[1]

    def pass_args(self, odr: OpenDriveMap, rows: np.ndarray, dt: float, plan: PlanView) -> tuple:
        """The arguments of ``motion_kernel.advance_and_place`` after ``rows`` and the time,
        for ``rows`` all on the road of ``plan``, with steps of ``dt`` s; kept while none of
        these, the lane profile or whether a lateral transition runs changes (the tables'
        arrays are updated in place; the tables as plain tuples, see kernels.tables)."""
        lanes, lateral = self.lanes(odr), self.n_lat > 0
        key = self._pass[0] if self._pass is not None else None
        if key is None or not (
            key[0] is rows and key[1] == dt and key[2] == lateral and key[3] is lanes
            and key[4] is plan
        ):  # fmt: skip
            road = RoadArrays(*plan.arrays())
            tail = (dt, lateral, tuple(self.arrays), tuple(lanes), tuple(road))
            self._pass = ((rows, dt, lateral, lanes, plan), tail)
        return self._pass[1]

    def mark_stale(self, k: int, lane_only: bool = False) -> None:
        """Row ``k``'s road, lane or ``against`` changed (``lane_only``: its lane alone): its
        direction is recomputed at the next refresh."""
        self.keep[k] = lane_only and (self.keep[k] or not self.stale[k])
        self.stale[k] = True
        self.any_stale = True

    def refresh(self, odr: OpenDriveMap) -> None:
        """Driving directions of rows whose road or lane changed. A row that changed lanes
        on its road goes on the way it went (OpenSCENARIO's LaneChangeAction moves an entity
        sideways, it does not turn it round): ``against`` is set anew for its lane."""
        if not self.any_stale:
            return
        for k in np.flatnonzero(self.stale).tolist():
            road = self.road[k]
            d = forward(odr, road, int(self.lane[k])) if road else 1.0
            if self.keep[k] and road:
                self.against[k] = d != self.direction[k]
            else:
                self.direction[k] = -d if self.against[k] else d
        self.stale[:] = False
        self.keep[:] = False
        self.any_stale = False


class _Column:
    """An Actor attribute stored in its row of the ActorTable column of the same name."""

    def __init__(self, cast: type, marks_stale: bool = False, lane_only: bool = False) -> None:
        self.cast, self.marks_stale, self.lane_only = cast, marks_stale, lane_only

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, obj: Actor | None, owner: type | None = None) -> object:
        if obj is None:
            return self
        return self.cast(getattr(obj.table, self.name)[obj.k])

    def __set__(self, obj: Actor, value: object) -> None:
        getattr(obj.table, self.name)[obj.k] = value
        if self.marks_stale:
            obj.table.mark_stale(obj.k, self.lane_only)


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
    lane = _Column(int, marks_stale=True, lane_only=True)
    against = _Column(bool, marks_stale=True)
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
        tb, k = self.table, self.k
        self._long = value
        tb.has_long[k] = value is not None
        tb.long_targets.pop(k, None)
        if value is not None:
            tb.long_par[k] = value.row()
            if value.target is not None:
                tb.long_targets[k] = value.target
        tb.motion_version += 1

    @property
    def lat(self) -> LateralTransition | None:
        """The running lateral transition."""
        return self._lat

    @lat.setter
    def lat(self, value: LateralTransition | None) -> None:
        tb, k = self.table, self.k
        self._lat = value
        tb.n_lat += (value is not None) - bool(tb.has_lat[k])
        tb.has_lat[k] = value is not None
        tb.lat_offsets.pop(k, None)
        if value is not None:
            tb.lat_par[k] = value.row(tb.code_of(value.road))
            if value.offset_of is not None:
                tb.lat_offsets[k] = value.offset_of
        tb.motion_version += 1

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
    if rd.straight:
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
    odr: OpenDriveMap,
    actors: list[Actor],
    rows: np.ndarray,
    now: float,
    dt: float,
    command: CommandArrays | None = None,
) -> np.ndarray | None:
    """Advance the road actors in table ``rows`` (indices into ``actors``, which share one
    table) by one step to scenario time ``now``: speeds and s, then lateral positions, in one
    compiled pass each; goals that follow other entities are read before each pass.
    ``command``: the commands' table, whose ``command_kernel.command_step`` runs in the same
    compiled call when the rows are on one road and the pass ends no transition; returns its
    result (None: not run)."""
    if not len(rows):
        return None
    tb = actors[0].table
    tb.refresh(odr)
    groups = tb.groups(rows)
    if groups is not tb.straight_groups:  # on straight roads only: kappa already 0
        for road, r in groups:
            # straight: 0 (rows may come from a curved road)
            tb.kappa[r] = 0.0 if odr.road(road).straight else curvature(odr, road, tb.s[r])
        if all(odr.road(road).straight for road, _ in groups):
            tb.straight_groups = groups
    read_targets(tb)
    one = _one_pass_road(odr, tb, rows, groups)
    if one is not None:  # the whole step in one compiled call
        road, plan = one
        args = (rows, now, *tb.pass_args(odr, rows, dt, plan))
        if command is None:
            ended, missing, lat_ended, placed = MK.advance_and_place(*args)
        else:
            ended, missing, lat_ended, placed, changed = CK.advance_and_command(
                *args, tuple(command)
            )
            if not ended and placed:
                return changed
        finish_pass(odr, actors, rows, road, ended, missing, lat_ended, placed)
        return None
    ended = MK.advance_long(rows, now, dt, tuple(tb.arrays))
    end_long(actors, rows, ended)
    if tb.n_lat:
        _advance_lateral(odr, actors, rows, now, dt)
    for road, r in groups:
        place_on_road(odr, road, tb, r)
    return None


def finish_pass(
    odr: OpenDriveMap,
    actors: list[Actor],
    rows: np.ndarray,
    road: str,
    ended: int,
    missing: int,
    lat_ended: int,
    placed: bool,
) -> None:
    """After ``motion_kernel.advance_and_place`` of ``rows`` on ``road`` (its results): remove
    the ended transitions, and when it did not place the rows (a lateral transition ended or
    missed its lane), put them on their lanes and place them."""
    end_long(actors, rows, ended)
    if not placed:
        _end_lateral(odr, actors, rows, missing, lat_ended)
        place_on_road(odr, road, actors[0].table, rows)


def quiet_motion(odr: OpenDriveMap, table: ActorTable, rows: np.ndarray, dt: float) -> tuple | None:
    """The arguments of ``motion_kernel.advance_and_place`` after the time for ``rows``, when
    their step can run inside the quiet step's compiled call: all on one straight road of
    lines and arcs, no lateral offset following another entity (read in Python every step);
    else None. Goals following other entities are read by the caller before the call
    (``read_targets``)."""
    if not len(rows):
        return None
    table.refresh(odr)
    groups = table.groups(rows)
    one = _one_pass_road(odr, table, rows, groups)
    if one is None or groups is not table.straight_groups:
        return None
    return (rows, *table.pass_args(odr, rows, dt, one[1]))


def _one_pass_road(
    odr: OpenDriveMap, table: ActorTable, rows: np.ndarray, groups: list[tuple[str, np.ndarray]]
) -> tuple[str, PlanView] | None:
    """The road of ``rows`` (grouped by road as ``groups``) and its PlanView when their step
    runs in one compiled pass: all on one road of lines and arcs, and no lateral offset
    following another entity (read in Python between the passes); else None."""
    if table.lat_offsets or len(groups) != 1 or groups[0][1] is not rows:
        return None
    plan = odr.road(groups[0][0]).plan_view
    return None if plan is None else (groups[0][0], plan)


def read_targets(table: ActorTable) -> None:
    """Read the goals of the running speed transitions that follow other entities."""
    for k, target in table.long_targets.items():
        table.long_par[k, MK.L_GOAL] = target()


def end_long(actors: list[Actor], rows: np.ndarray, ended: int) -> None:
    """Remove the ``ended`` longitudinal transitions the pass marked done."""
    if ended:
        tb = actors[0].table
        for k in rows[tb.long_done[rows]].tolist():
            actors[k].long = None


def _advance_lateral(
    odr: OpenDriveMap, actors: list[Actor], rows: np.ndarray, now: float, dt: float
) -> None:
    """The lateral pass of ``advance_road_actors``; the rows whose transition ended are put
    on their target lane."""
    tb = actors[0].table
    for k, offset in tb.lat_offsets.items():
        tb.lat_par[k, MK.T_OFFSET] = offset()
    missing, ended = MK.advance_lat(rows, now, dt, tuple(tb.arrays), tuple(tb.lanes(odr)))
    _end_lateral(odr, actors, rows, missing, ended)


def _end_lateral(
    odr: OpenDriveMap, actors: list[Actor], rows: np.ndarray, missing: int, ended: int
) -> None:
    """After the lateral pass: the error of a ``missing`` target lane (its row, -1: none);
    the rows whose transition ended are put on their target lane."""
    tb = actors[0].table
    if missing >= 0:
        a = actors[missing]
        odr.road(a.lat.road).lane_t(a.lat.lane, a.s)  # raises: no such lane here
    if ended:
        for k in rows[tb.lat_done[rows]].tolist():
            a = actors[k]
            a.lane, a.lat = a.lat.lane, None


def place_on_road(odr: OpenDriveMap, road: str, table: ActorTable, rows: np.ndarray) -> None:
    """World pose (x, y, z, heading) of table ``rows`` on ``road`` from their road
    coordinates (compiled for roads of lines and arcs, else from the numpy road pose)."""
    table.refresh(odr)
    tb = table
    rd = odr.road(road)
    if rd.plan_view is not None:
        MK.place_rows(rows, tuple(RoadArrays(*rd.plan_view.arrays())), tuple(tb.arrays))
        return
    x, y, z, h_ref = odr.road_pose(road, tb.s[rows], tb.t[rows])
    MK.place_posed(rows, x, y, z, h_ref, tuple(tb.arrays))


def place_actor(odr: OpenDriveMap, a: Actor) -> None:
    """World pose of one road actor from its road coordinates."""
    place_on_road(odr, a.road, a.table, np.array([a.k]))
