"""Which actors a WorldState holds: everything, or what lies around one vehicle (the ego).

A closed loop's consumers (sensors, perception truth, TTC, the stack) need the actors within
some range of the ego, not the whole city. Reading only those is what makes the read cheap:
SUMO finds them with its own spatial index (a context subscription on the ego, evaluated in C++
inside ``simulationStep``), and Python touches only their values. benchmarks/worldstate.py
measures both.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from operator import itemgetter
from types import ModuleType
from typing import NamedTuple

from hiyari.errors import HiyariError


@dataclass(frozen=True)
class ReadScope:
    """Read only the actors around the vehicle ``center`` (the ego) every step.

    The scoped WorldState holds, at every step:

    - the ``center`` vehicle itself;
    - every vehicle whose SUMO position (the front-bumper centre) and every person whose SUMO
      position lies within ``radius`` m (2-D) of the centre's front-bumper centre;
    - every actor named in ``include`` (scenario entities a storyboard may test wherever they
      are), when it is in the network.

    Rows come in the same order as in the full state (vehicles, then persons, each sorted by
    id), with bit-identical values, except one documented difference: a person's acceleration
    is differenced from its speed at the previous step, so a person entering the scope shows
    0 m/s^2 on its first scoped step (as a newly departed person does in the full state). Not
    in the scope: vehicles parked off the lanes and persons riding in a vehicle (SUMO collects
    the scope from the lanes). While ``center`` is not in the network (before it is inserted,
    after it has arrived) every actor is read, so nothing is silently missing.

    Choose ``radius`` as the farthest consumer's range plus the largest front-to-centre
    offsets (half a bus, half the ego): for the closed loop's 300 m ground-truth eye that is
    about 310 m; for sensors alone the largest sensor range plus ~10 m.
    """

    center: str
    radius: float
    include: tuple[str, ...] = ()

    def validate(self) -> None:
        """Raise HiyariError for an empty centre id or a non-positive radius."""
        if not self.center:
            raise HiyariError("read scope: the centre vehicle id is empty")
        if not self.radius > 0:
            raise HiyariError(f"read scope: radius must be positive, got {self.radius} m")


class Columns(NamedTuple):
    """One domain's raw SUMO values, one entry per actor (the reader turns them into arrays)."""

    ids: Sequence[str]
    pos: Sequence[tuple[float, float, float]]  # SUMO position (vehicle front bumper), m
    angle: Sequence[float]  # SUMO compass angle, degrees
    speed: Sequence[float]  # m/s
    accel: Sequence[float] | None  # m/s^2 (vehicles; None for persons)
    lane: Sequence[str]


class ContextScope:
    """The ego's context subscriptions in SUMO and their results as Columns.

    libsumo files the results of both domains (vehicles, persons) under the ego's id in one
    dictionary keyed by actor id, so a vehicle and a person sharing an id would overwrite each
    other: the person subscription asks for one person-only variable (the vehicle it rides,
    empty when walking) as a marker, and such clashes are read through the getters instead.
    """

    def __init__(self, sumo: ModuleType, scope: ReadScope) -> None:
        scope.validate()
        self.scope = scope
        tc = sumo.constants
        self._sumo = sumo
        self._c = sumo._libsumo
        self._pos, self._angle, self._speed = tc.VAR_POSITION3D, tc.VAR_ANGLE, tc.VAR_SPEED
        self._accel, self._lane, self._marker = tc.VAR_ACCELERATION, tc.VAR_LANE_ID, tc.VAR_VEHICLE
        self._domains = (tc.CMD_GET_VEHICLE_VARIABLE, tc.CMD_GET_PERSON_VARIABLE)
        shared = [self._pos, self._angle, self._speed]
        self._vars = (shared + [self._accel, self._lane], shared + [self._lane, self._marker])
        # one tuple of values per actor in the order of Columns' fields
        self._vget = itemgetter(*self._vars[0])
        self._pget = itemgetter(*self._vars[1][:4])
        self._subscribed = False

    def subscribe(self) -> None:
        """Start the ego's context subscriptions (the ego must be in the network)."""
        sub = self._sumo.vehicle.subscribeContext
        for domain, variables in zip(self._domains, self._vars, strict=True):
            sub(self.scope.center, domain, self.scope.radius, variables)
        self._subscribed = True

    def pause(self) -> None:
        """Stop the subscriptions while nobody reads (SUMO evaluates them in every step); the
        next ``read`` starts them again."""
        if self._subscribed:
            unsub = self._sumo.vehicle.unsubscribeContext
            try:
                for domain in self._domains:
                    unsub(self.scope.center, domain, self.scope.radius)
            except self._sumo.TraCIException:
                pass  # the centre has left: SUMO dropped its subscriptions with it
            self._subscribed = False

    def read(self, vehicle_ids: Callable[[], Sequence[str]]) -> tuple[Columns, Columns] | None:
        """(vehicles, persons) in scope now, or None when the centre is not in the network.

        ``vehicle_ids``: a callable giving the vehicles in the network (only called while the
        centre has no subscription yet, to see whether it has arrived).
        """
        c = self._c
        res = c.vehicle_getContextSubscriptionResults(self.scope.center) if self._subscribed else {}
        if not res:
            # the centre's own entry is always there while it exists: it has gone, or not come
            self._subscribed = False
            if self.scope.center not in vehicle_ids():
                return None
            self.subscribe()
            res = c.vehicle_getContextSubscriptionResults(self.scope.center)
        accel, marker = self._accel, self._marker
        vids: list[str] = []
        pids: list[str] = []
        clash: list[str] = []
        for k, v in res.items():
            if accel not in v:
                pids.append(k)
            elif marker in v:
                clash.append(k)
            else:
                vids.append(k)
        extra_v, extra_p = self._outside(res, clash)
        veh = self._columns(res, vids, extra_v, True)
        per = self._columns(res, pids, extra_p, False)
        return veh, per

    def _outside(self, res: dict, clash: list[str]) -> tuple[dict, dict]:
        """Values from the getters for clashing ids (within the radius) and for ``include``
        actors outside the scope: ({vehicle id: values}, {person id: values})."""
        extra_v: dict[str, dict] = {}
        extra_p: dict[str, dict] = {}
        if not clash and all(i in res for i in self.scope.include):
            return extra_v, extra_p
        c = self._c
        cx, cy = c.vehicle_getPosition(self.scope.center)
        r2 = self.scope.radius**2
        for aid in clash:
            for values, out in ((self._vehicle(aid), extra_v), (self._person(aid), extra_p)):
                x, y, _ = values[self._pos]
                if (x - cx) ** 2 + (y - cy) ** 2 <= r2:
                    out[aid] = values
        for aid in self.scope.include:
            if aid in res and aid not in clash:
                continue
            for getter, out in ((self._vehicle, extra_v), (self._person, extra_p)):
                if aid not in out:
                    try:
                        out[aid] = getter(aid)
                    except self._sumo.TraCIException:
                        pass  # not in the network (or not of this domain) now
        return extra_v, extra_p

    def _vehicle(self, aid: str) -> dict:
        c = self._c
        return {
            self._pos: c.vehicle_getPosition3D(aid),
            self._angle: c.vehicle_getAngle(aid),
            self._speed: c.vehicle_getSpeed(aid),
            self._accel: c.vehicle_getAcceleration(aid),
            self._lane: c.vehicle_getLaneID(aid),
        }

    def _person(self, aid: str) -> dict:
        c = self._c
        return {
            self._pos: c.person_getPosition3D(aid),
            self._angle: c.person_getAngle(aid),
            self._speed: c.person_getSpeed(aid),
            self._lane: c.person_getLaneID(aid),
        }

    def _columns(self, res: dict, ids: list[str], extra: dict, vehicles: bool) -> Columns:
        if extra:
            res = {**{k: res[k] for k in ids}, **extra}
            ids = sorted(res)  # SUMO lists actors sorted by id; extras keep that order
        if not ids:
            return Columns((), (), (), (), () if vehicles else None, ())
        if vehicles:
            pos, angle, speed, accel, lane = zip(
                *map(self._vget, map(res.__getitem__, ids)), strict=True
            )
            return Columns(ids, pos, angle, speed, accel, lane)
        pos, angle, speed, lane = zip(*map(self._pget, map(res.__getitem__, ids)), strict=True)
        return Columns(ids, pos, angle, speed, None, lane)
