"""Which actors a WorldState holds: everything, or what lies around one vehicle (the ego).

A closed loop's consumers (sensors, perception truth, TTC, the stack) need the actors within
some range of the ego, not the whole city. Reading only those is what makes the read cheap.
:class:`ScopeScan` finds them without a context subscription (that costs a spatial search
inside every ``simulationStep``; the step's events come from one simulation subscription): now
and then it reads every actor's position (compiled getters, one call per actor) and keeps as
candidates those that could reach the radius before the next scan; every step it reads the
candidates' positions, keeps exactly those within the radius and reads their other values.
benchmarks/worldstate.py measures it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from itertools import chain, compress
from types import ModuleType
from typing import NamedTuple

import numpy as np

from hiyari.errors import HiyariError
from hiyari.traffic.state_kernel import within


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
    """One domain's (vehicles' or persons') getters, candidates and speed bound."""

    def __init__(self, c: ModuleType, prefix: str, vehicles: bool) -> None:
        get = lambda name: getattr(c, f"{prefix}_{name}")  # noqa: E731
        self.ids, self.pos = get("getIDList"), get("getPosition3D")
        self.max_speed = get("getMaxSpeed")
        self.values = (get("getAngle"), get("getSpeed"), get("getLaneID"))
        self.accel = get("getAcceleration") if vehicles else None
        self.vehicles = vehicles
        self.candidates: set[str] = set()
        self.pinned: set[str] = set()  # moved by commands: read every step, whatever the bound
        self.known: set[str] = set()  # actors whose max speed is in ``v_max``
        self.v_max = 0.0  # m/s, the largest max speed of this domain's actors
        self.scan_time = math.nan  # s; NaN: scan at the next read
        self.scan_xy = (0.0, 0.0)  # the centre's SUMO position at the scan, m
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

    def learn(self, present: set[str]) -> None:
        """Fold the max speeds of actors not seen before into ``v_max``."""
        new = present - self.known
        if new:
            self.v_max = max(self.v_max, *map(self.max_speed, new))
            self.known |= new

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
    n = len(ids)
    return np.fromiter(chain.from_iterable(map(getter, ids)), float, 3 * n).reshape(n, 3)


class ScopeScan:
    """The actors of a :class:`ReadScope` at the current step, as Columns.

    The exact rule is applied every step to a candidate set; the candidate set is exact as long
    as no actor outside it can have come within ``radius``. At a scan (every position of a
    domain: vehicles, persons) the candidates are the domain's actors within
    ``radius + margin``. Between scans an actor moves at most its domain's ``v_max`` m/s (the
    largest SUMO max speed of the domain's actors seen) plus, per step, one lateral jump of a
    lane change (the widest lane of the network); the centre's own displacement is measured. A
    domain is scanned again as soon as these bounds together could exceed ``margin``, and both
    at once when something breaks them: a teleport, a vehicle starting or ending to park or
    stop, any vehicle at a stop (persons board and alight there, jumping to or from their
    vehicle), a departing vehicle with persons aboard, a step not read, a candidate gone.
    Persons riding a vehicle at a scan move as fast as it: they stay candidates until the next
    scan (persons board only at stops and at triggered departures: until one of those has
    happened, nobody rides and this check is skipped). A network without internal junction lanes (vehicles jump across junctions) is scanned
    every step. Actors moved or sped by Simulation's commands (:meth:`pin`: no bound holds for
    them) and departing actors are candidates until they leave; a move through libsumo
    directly, bypassing Simulation, is not seen.
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
        self._riding = c.person_getVehicle
        self._aboard = c.vehicle_getPersonNumber
        self._include = frozenset(scope.include)
        self._stopped: set[str] = set()
        # persons board only at stops and triggered departures: none can ride before either
        self._may_ride = False
        self._cx = self._cy = 0.0  # the centre's SUMO position at the latest read, m
        self._read_time = math.nan
        # the step's events in one call (SUMO collects them in the step anyway)
        tc = sumo.constants
        self._departed = (tc.VAR_DEPARTED_VEHICLES_IDS, tc.VAR_DEPARTED_PERSONS_IDS)
        self._arrived = (tc.VAR_ARRIVED_VEHICLES_IDS, tc.VAR_ARRIVED_PERSONS_IDS)
        self._stops = (tc.VAR_STOP_STARTING_VEHICLES_IDS, tc.VAR_STOP_ENDING_VEHICLES_IDS)
        self._jumps = (
            tc.VAR_TELEPORT_STARTING_VEHICLES_NUMBER,
            tc.VAR_TELEPORT_ENDING_VEHICLES_NUMBER,
            tc.VAR_PARKING_STARTING_VEHICLES_NUMBER,
            tc.VAR_PARKING_ENDING_VEHICLES_NUMBER,
        )
        sumo.simulation.subscribe([*self._departed, *self._arrived, *self._stops, *self._jumps])
        self._results = c.simulation_getSubscriptionResults

    def pin(self, ids: Iterable[str], persons: bool = False) -> None:
        """Read these actors every step until they leave (commands move them off any bound)."""
        d = self._per if persons else self._veh
        ids = list(ids)
        d.pinned.update(ids)
        d.add(ids)

    def pause(self) -> None:
        """Steps will go unread: scan at the next read."""
        self._veh.scan_time = self._per.scan_time = math.nan

    def read(self) -> tuple[Columns, Columns] | None:
        """(vehicles, persons) in scope now, or None when the centre is not in the network."""
        now = self._c.simulation_getTime()
        self._events(now)
        try:
            veh = self._vehicles(now)
            return None if veh is None else (veh, self._persons(now))
        except self._error:  # an actor gone unannounced (removed), or the centre
            self.pause()
            veh = self._vehicles(now)
            return None if veh is None else (veh, self._persons(now))

    def _events(self, now: float) -> None:
        """Departures and arrivals of the last step; what forces a scan."""
        stepped = now - self._read_time
        self._read_time = now
        if stepped == 0.0:
            return  # a second read at the same time: the step's events are in already
        if not abs(stepped - self._dt) <= 1e-9 * max(1.0, now):
            self.pause()  # steps went unread: their events are lost
        ev = self._results()
        (dv, dp), (av, ap), (start, end) = self._departed, self._arrived, self._stops
        self._veh.add(ev[dv])
        self._per.add(ev[dp])
        self._veh.drop(ev[av])
        self._per.drop(ev[ap])
        self._stopped.update(ev[start])
        self._stopped.difference_update(ev[end])
        j0, j1, j2, j3 = self._jumps
        if ev[start] or ev[end]:
            self._may_ride = True
        if self._stopped or ev[start] or ev[end] or ev[j0] or ev[j1] or ev[j2] or ev[j3]:
            self.pause()
        elif ev[dv] and any(map(self._aboard, ev[dv])):  # a triggered departure
            self._may_ride = True
            self._per.scan_time = math.nan

    def _due(self, d: _Domain, now: float) -> bool:
        """Whether an actor of ``d`` outside the candidates could be within the radius now."""
        since = now - d.scan_time
        if since != since:
            return True
        steps = round(since / self._dt)
        if not steps:
            return False
        closed = d.v_max * since + self._jump * steps
        closed += math.hypot(self._cx - d.scan_xy[0], self._cy - d.scan_xy[1])
        # the slack keeps rounding of the distances away from the bound
        return closed >= self.scope.margin - 1e-6 * (self.scope.radius + self.scope.margin)

    def _vehicles(self, now: float) -> Columns | None:
        """The vehicles in scope; None when the centre is not in the network."""
        d = self._veh
        if d.scan_time == d.scan_time:
            # the centre alone first: a scan due now reads every position anyway (a centre
            # gone since raises, and read() scans)
            self._cx, self._cy, _ = d.pos(self.scope.center)
            if not self._due(d, now):
                ids = d.order()
                return self._filter(d, ids, positions(d.pos, ids))
        ids = d.ids()
        if self.scope.center not in ids:
            self.pause()
            return None
        xyz = positions(d.pos, ids)
        k = ids.index(self.scope.center)
        self._cx, self._cy = xyz[k, 0], xyz[k, 1]
        return self._scan(d, now, list(ids), xyz)

    def _persons(self, now: float) -> Columns:
        d = self._per
        if not self._due(d, now):
            ids = d.order()
            return self._filter(d, ids, positions(d.pos, ids))
        ids = list(d.ids())
        return self._scan(d, now, ids, positions(d.pos, ids))

    def _scan(self, d: _Domain, now: float, ids: list[str], xyz: np.ndarray) -> Columns:
        """New candidates of ``d`` from every position ``xyz`` of its actors ``ids``; the
        domain's actors in scope."""
        reach = within(xyz, self._cx, self._cy, self.scope.radius + self.scope.margin)
        present = set(ids)
        d.learn(present)
        near = set(compress(ids, reach.tolist()))
        near |= (d.pinned | self._include) & present
        if d.vehicles:
            self._stopped &= present
        elif self._may_ride:
            near.update(compress(ids, map(self._riding, ids)))
        d.set_candidates(near)
        d.scan_time = now
        d.scan_xy = (self._cx, self._cy)
        return self._filter(d, ids, xyz)

    def _filter(self, d: _Domain, ids: list[str], xyz: np.ndarray) -> Columns:
        """The actors of ``ids`` (SUMO positions ``xyz``) within the radius of the centre, and
        the included ones, exactly."""
        keep = within(xyz, self._cx, self._cy, self.scope.radius)
        if self._include:
            keep |= np.fromiter((i in self._include for i in ids), bool, len(ids))
        flags = keep.tolist()
        if all(flags):
            return d.columns(ids, xyz)
        return d.columns(list(compress(ids, flags)), xyz[keep])
