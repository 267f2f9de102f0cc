"""Which actors a WorldState holds: everything, or what lies around one vehicle (the ego).

A closed loop's consumers (sensors, perception truth, TTC, the stack) need the actors within
some range of the ego, not the whole city. Reading only those is what makes the read cheap.
:class:`ScopeScan` finds them without a SUMO subscription (a context subscription costs a
spatial search inside every ``simulationStep``): now and then it reads every actor's position
(compiled getters, one call per actor) and keeps as candidates those that could reach the
radius before the next scan; every step it reads the candidates' positions, keeps exactly those
within the radius and reads their other values. benchmarks/worldstate.py measures it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from itertools import compress
from types import ModuleType
from typing import NamedTuple

import numpy as np

from hiyari.errors import HiyariError


@dataclass(frozen=True)
class ReadScope:
    """Read only the actors around the vehicle ``center`` (the ego) every step.

    The scoped WorldState holds, at every step, the rows of the full state (every vehicle and
    person in the network) that are:

    - the ``center`` vehicle itself;
    - every vehicle and person whose SUMO position (a vehicle's front-bumper centre; for a
      person riding in a vehicle, where SUMO puts it) lies within ``radius`` m (2-D,
      ``hypot(dx, dy) <= radius``) of the centre's front-bumper centre, parked vehicles
      included;
    - every actor named in ``include`` (scenario entities a storyboard may test wherever they
      are), when it is in the network.

    Rows come in the same order as in the full state (vehicles, then persons, each sorted by
    id), with bit-identical values, except one documented difference: a person's acceleration
    is differenced from its speed at the previous step, so a person entering the scope shows
    0 m/s^2 on its first scoped step (as a newly departed person does in the full state). While
    ``center`` is not in the network (before it is inserted, after it has arrived) every actor
    is read, so nothing is silently missing.

    Choose ``radius`` as the farthest consumer's range plus the largest front-to-centre
    offsets (half a bus, half the ego): for the closed loop's 300 m ground-truth eye that is
    about 310 m; for sensors alone the largest sensor range plus ~10 m. ``margin`` (m) is a
    cost knob only, never a change of the result: candidates are the actors within
    ``radius + margin`` at a scan of every position, and a scan comes again before any other
    actor could have closed the margin (see :class:`ScopeScan`).
    """

    center: str
    radius: float
    include: tuple[str, ...] = ()
    margin: float = 50.0

    def validate(self) -> None:
        """Raise HiyariError for an empty centre id, a non-positive radius or a negative
        margin."""
        if not self.center:
            raise HiyariError("read scope: the centre vehicle id is empty")
        if not self.radius > 0:
            raise HiyariError(f"read scope: radius must be positive, got {self.radius} m")
        if not self.margin >= 0:
            raise HiyariError(f"read scope: margin must be >= 0, got {self.margin} m")


class Columns(NamedTuple):
    """One domain's raw SUMO values, one entry per actor (the reader turns them into arrays)."""

    ids: Sequence[str]
    pos: np.ndarray  # (N, 3) SUMO position (vehicle front bumper), m
    angle: Sequence[float]  # SUMO compass angle, degrees
    speed: Sequence[float]  # m/s
    accel: Sequence[float] | None  # m/s^2 (vehicles; None for persons)
    lane: Sequence[str]


class _Domain:
    """One domain's (vehicles' or persons') getters and candidate bookkeeping."""

    def __init__(self, c: ModuleType, prefix: str, vehicles: bool) -> None:
        get = lambda name: getattr(c, f"{prefix}_{name}")  # noqa: E731
        self.ids, self.pos, self.max_speed = (
            get("getIDList"),
            get("getPosition3D"),
            get("getMaxSpeed"),
        )
        self.values = (get("getAngle"), get("getSpeed"), get("getLaneID"))
        self.accel = get("getAcceleration") if vehicles else None
        self.vehicles = vehicles
        self.candidates: set[str] = set()
        self.pinned: set[str] = set()  # moved by commands: read every step, whatever the bound
        self.known: set[str] = set()  # actors whose max speed is in the bound
        self._order: list[str] | None = []

    def add(self, ids: Iterable[str]) -> None:
        before = len(self.candidates)
        self.candidates.update(ids)
        if len(self.candidates) != before:
            self._order = None

    def drop(self, ids: Sequence[str]) -> None:
        if ids:
            self.candidates.difference_update(ids)
            self.pinned.difference_update(ids)
            self._order = None

    def set_candidates(self, ids: set[str]) -> None:
        self.candidates = ids
        self._order = None

    def order(self) -> list[str]:
        """Candidates sorted as SUMO lists them (by id)."""
        if self._order is None:
            self._order = sorted(self.candidates)
        return self._order

    def columns(self, ids: list[str], pos: np.ndarray) -> Columns:
        angle, speed, lane = self.values
        accel = list(map(self.accel, ids)) if self.accel is not None else None
        return Columns(
            ids, pos, list(map(angle, ids)), list(map(speed, ids)), accel, list(map(lane, ids))
        )


def positions(
    getter: Callable[[str], tuple[float, float, float]], ids: Sequence[str]
) -> np.ndarray:
    """(N, 3) SUMO positions of ``ids`` through ``getter``, m."""
    return np.array(list(map(getter, ids)), dtype=float).reshape(len(ids), 3)


class ScopeScan:
    """The actors of a :class:`ReadScope` at the current step, as Columns.

    The exact rule is applied every step to a candidate set; the candidate set is exact as long
    as no actor outside it can have come within ``radius``. At a scan (every actor's position)
    the candidates are the actors within ``radius + margin``. Between scans an actor moves at
    most ``v_max`` m/s (the largest SUMO max speed of any actor seen: vehicles, persons, and so
    riding persons) plus, per step, one lateral jump of a lane change (the widest lane of the
    network); the centre's own displacement is measured. A scan comes again as soon as these
    bounds together could exceed ``margin``, and at once when something breaks them: a
    teleport, a vehicle starting or ending to park, any vehicle at a stop (persons board and
    alight there, jumping to or from their vehicle), a step not read, a candidate gone. A
    network without internal junction lanes (vehicles jump across junctions) is scanned every
    step. Actors moved or sped by commands (:meth:`pin`) and departing actors are candidates
    until they leave.
    """

    def __init__(self, sumo: ModuleType, scope: ReadScope) -> None:
        scope.validate()
        self.scope = scope
        c = sumo._libsumo
        self._c = c
        self._error = sumo.TraCIException
        self._dt = c.simulation_getDeltaT()
        lanes = c.lane_getIDList()
        junction_lanes = any(lane.startswith(":") for lane in lanes)
        self._jump = max(map(c.lane_getWidth, lanes), default=0.0) if junction_lanes else math.inf
        self._veh = _Domain(c, "vehicle", True)
        self._per = _Domain(c, "person", False)
        self._include = frozenset(scope.include)
        self._v_max = 0.0
        self._stopped: set[str] = set()
        self._scan_time = math.nan  # NaN: scan at the next read
        self._scan_xy = (0.0, 0.0)
        self._read_time = math.nan

    def pin(self, ids: Iterable[str], persons: bool = False) -> None:
        """Read these actors every step until they leave (commands move them off any bound)."""
        d = self._per if persons else self._veh
        ids = list(ids)
        d.pinned.update(ids)
        d.add(ids)

    def pause(self) -> None:
        """Steps will go unread: scan at the next read."""
        self._scan_time = math.nan

    def read(self) -> tuple[Columns, Columns] | None:
        """(vehicles, persons) in scope now, or None when the centre is not in the network."""
        c = self._c
        now = c.simulation_getTime()
        self._events(now)
        center = self.scope.center
        if self._scan_time != self._scan_time and center not in c.vehicle_getIDList():
            return None
        try:
            cx, cy, _ = c.vehicle_getPosition3D(center)
        except self._error:
            self._scan_time = math.nan
            return None
        if self._scan_due(now, cx, cy):
            self._scan(now, cx, cy)
        try:
            return self._columns(self._veh, cx, cy), self._columns(self._per, cx, cy)
        except self._error:  # a candidate has gone without an arrival (e.g. removed)
            self._scan(now, cx, cy)
            return self._columns(self._veh, cx, cy), self._columns(self._per, cx, cy)

    def _events(self, now: float) -> None:
        """Departures and arrivals of the last step; what forces a scan."""
        c = self._c
        stepped = now - self._read_time
        self._read_time = now
        if stepped == 0.0:
            return  # a second read at the same time: the step's events are in already
        if not abs(stepped - self._dt) <= 1e-9 * max(1.0, now):
            self._scan_time = math.nan  # steps went unread: their events are lost
        self._veh.add(c.simulation_getDepartedIDList())
        self._per.add(c.simulation_getDepartedPersonIDList())
        self._veh.drop(c.simulation_getArrivedIDList())
        self._per.drop(c.simulation_getArrivedPersonIDList())
        if c.simulation_getStopStartingVehiclesNumber():
            self._stopped.update(c.simulation_getStopStartingVehiclesIDList())
        if c.simulation_getStopEndingVehiclesNumber():
            self._stopped.difference_update(c.simulation_getStopEndingVehiclesIDList())
        jumps = (
            c.simulation_getStartingTeleportNumber()
            or c.simulation_getEndingTeleportNumber()
            or c.simulation_getParkingStartingVehiclesNumber()
            or c.simulation_getParkingEndingVehiclesNumber()
        )
        if jumps or self._stopped:
            self._scan_time = math.nan

    def _scan_due(self, now: float, cx: float, cy: float) -> bool:
        since = now - self._scan_time
        if since != since:
            return True
        steps = round(since / self._dt)
        if steps == 0:
            return False
        closed = self._v_max * since + self._jump * steps
        closed += math.hypot(cx - self._scan_xy[0], cy - self._scan_xy[1])
        # the slack keeps rounding of the distances away from the bound
        return closed >= self.scope.margin - 1e-6 * (self.scope.radius + self.scope.margin)

    def _scan(self, now: float, cx: float, cy: float) -> None:
        """Every actor's position: the candidates, the speed bound, the stopped vehicles."""
        reach = self.scope.radius + self.scope.margin
        for d in (self._veh, self._per):
            ids = d.ids()
            new = [i for i in ids if i not in d.known]
            if new:
                self._v_max = max(self._v_max, *map(d.max_speed, new))
                d.known.update(new)
            xyz = positions(d.pos, ids)
            near = np.hypot(xyz[:, 0] - cx, xyz[:, 1] - cy) <= reach
            present = set(ids)
            d.pinned &= present
            d.set_candidates(
                set(compress(ids, near.tolist())) | d.pinned | (self._include & present)
            )
            if d.vehicles:
                self._stopped &= present
        self._scan_time = now
        self._scan_xy = (cx, cy)

    def _columns(self, d: _Domain, cx: float, cy: float) -> Columns:
        """The candidates within the radius (and the included ones), exactly."""
        ids = d.order()
        xyz = positions(d.pos, ids)
        keep = np.hypot(xyz[:, 0] - cx, xyz[:, 1] - cy) <= self.scope.radius
        if self._include:
            keep |= np.fromiter((i in self._include for i in ids), bool, len(ids))
        if not keep.all():
            ids = list(compress(ids, keep.tolist()))
            xyz = xyz[keep]
        return d.columns(ids, xyz)
