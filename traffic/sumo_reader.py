"""Read one WorldState per step out of a running libsumo simulation.

What is read: every vehicle and person in the network (the default), or with a
:class:`~hiyari.traffic.read_scope.ReadScope` only the actors around the ego (a
:class:`~hiyari.traffic.read_scope.ScopeScan` finds them); :meth:`WorldStateReader.read_full`
reads everyone on demand either way.

How the full state is read: ``"getters"`` calls libsumo's compiled per-object getters (the SWIG
functions themselves, without libsumo's Python wrappers) in one pass per variable;
``"subscriptions"`` subscribes each actor to its variables at departure and fetches all results
with one ``getAllSubscriptionResults`` call per domain. In libsumo (in-process, no socket) the
getters are the cheaper of the two (benchmarks/worldstate.py measures both: the subscription
path also makes every simulation step slower), so they are the default. Both give identical
states. Static attributes (class, size) are read once per actor and kept in arrays.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from itertools import chain
from types import ModuleType
from typing import Literal

import numpy as np

from hiyari.traffic.actor_class import ActorClass, actor_class_from_vclass
from hiyari.traffic.read_scope import Columns, ReadScope, ScopeScan, positions
from hiyari.traffic.state_kernel import sumo_to_state
from hiyari.traffic.world_state import WorldState

ReadMode = Literal["getters", "subscriptions"]


class _ActorTable:
    """Per-actor static values (class, sizes), appended when an actor is first seen, and the
    last two speeds read with their times (persons' accelerations are differenced)."""

    def __init__(self) -> None:
        self.row: dict[str, int] = {}
        self.data = np.zeros((64, 4))  # cls, length, width, height
        self.speeds = np.full((64, 4), np.nan)  # time, speed of the latest read; of the one before

    def rows(
        self, ids: list[str], fetch: Callable[[str], tuple[float, float, float, float]]
    ) -> np.ndarray:
        idx = list(map(self.row.get, ids))
        if None in idx:
            for k, i in enumerate(ids):
                if idx[k] is None:
                    idx[k] = self._add(i, fetch(i))
        return np.array(idx, dtype=np.intp)

    def _add(self, actor_id: str, values: tuple[float, float, float, float]) -> int:
        r = len(self.row)
        if r == len(self.data):
            self.data = np.concatenate([self.data, np.zeros_like(self.data)])
            self.speeds = np.concatenate([self.speeds, np.full_like(self.speeds, np.nan)])
        self.data[r] = values
        self.row[actor_id] = r
        return r


class WorldStateReader:
    """Turns the current libsumo state into a WorldState; one reader per simulation."""

    def __init__(
        self,
        sumo: ModuleType,
        mode: ReadMode = "getters",
        scope: ReadScope | None = None,
    ) -> None:
        if mode not in ("getters", "subscriptions"):
            raise ValueError(f"unknown read mode {mode!r} (getters or subscriptions)")
        self._sumo = sumo
        self._mode = mode
        self._veh = _ActorTable()
        self._per = _ActorTable()
        self._edge_of: dict[str, str] = {}
        self._dt = sumo.simulation.getDeltaT()
        self._now = self._before = float("nan")  # the times of the latest two reads, s
        self._scope = ScopeScan(sumo, scope) if scope is not None else None
        # the SWIG functions themselves: libsumo's Python wrappers add a call layer per value
        c = sumo._libsumo
        self._time = c.simulation_getTime
        self._v = (
            c.vehicle_getIDList,
            c.vehicle_getPosition3D,
            c.vehicle_getAngle,
            c.vehicle_getSpeed,
            c.vehicle_getAcceleration,
            c.vehicle_getLaneID,
        )
        self._p = (
            c.person_getIDList,
            c.person_getPosition3D,
            c.person_getAngle,
            c.person_getSpeed,
            c.person_getLaneID,
        )
        if mode == "subscriptions":
            tc = sumo.constants
            self._veh_vars = [
                tc.VAR_POSITION3D,
                tc.VAR_ANGLE,
                tc.VAR_SPEED,
                tc.VAR_ACCELERATION,
                tc.VAR_LANE_ID,
            ]
            self._per_vars = [tc.VAR_POSITION3D, tc.VAR_ANGLE, tc.VAR_SPEED, tc.VAR_LANE_ID]
            if scope is None:  # the scope's own subscription includes the departures
                sumo.simulation.subscribe(
                    [tc.VAR_DEPARTED_VEHICLES_IDS, tc.VAR_DEPARTED_PERSONS_IDS]
                )

    @property
    def scope(self) -> ReadScope | None:
        """The read scope (None: every actor is read every step)."""
        return self._scope.scope if self._scope is not None else None

    def read(self) -> WorldState:
        """The WorldState at the simulation's current time: the scope's actors when a scope is
        set and its centre is in the network, else every actor."""
        if self._scope is not None:
            cols = self._scope.read()
            if cols is not None:
                return self._assemble(*cols)
        return self.read_full()

    def pause(self) -> None:
        """Nothing will be read for a while (bare stepping): the scope rescans afterwards."""
        if self._scope is not None:
            self._scope.pause()

    def pin(self, ids: Sequence[str], persons: bool = False) -> None:
        """Commands moved (or set the speed of) these actors: the scope reads them every step."""
        if self._scope is not None:
            self._scope.pin(ids, persons)

    def read_full(self) -> WorldState:
        """The WorldState with every vehicle and person in the network now."""
        if self._mode == "subscriptions":
            return self._assemble(*self._read_subscriptions())
        return self._assemble(*self._read_getters())

    def _vehicle_static(self, vid: str) -> tuple[float, float, float, float]:
        v = self._sumo.vehicle
        vclass = v.getVehicleClass(vid)
        # permission-free scripted actors (vClass "ignoring") say what they are by their shape
        cls = actor_class_from_vclass(v.getShapeClass(vid) if vclass == "ignoring" else vclass)
        return float(cls), v.getLength(vid), v.getWidth(vid), v.getHeight(vid)

    def _person_static(self, pid: str) -> tuple[float, float, float, float]:
        p = self._sumo.person
        return float(ActorClass.PEDESTRIAN), p.getLength(pid), p.getWidth(pid), p.getHeight(pid)

    def _assemble(self, veh: Columns, per: Columns) -> WorldState:
        time = self._time()
        if time != self._now:
            self._before, self._now = self._now, time
        nv, n = len(veh.ids), len(veh.ids) + len(per.ids)
        vrow = self._veh.rows(veh.ids, self._vehicle_static)
        prow = self._per.rows(per.ids, self._person_static)
        front = np.concatenate([veh.pos, per.pos]) if n > nv else veh.pos
        angle = np.fromiter(chain(veh.angle, per.angle), float, n)
        speed = np.fromiter(chain(veh.speed, per.speed), float, n)
        accel = np.empty(n)
        accel[:nv] = veh.accel
        # SUMO reports the front-bumper centre; the toolkit uses the rectangle centre. Persons
        # have no acceleration getter: their speeds are differenced over the last step
        xyz, heading, st = sumo_to_state(
            front,
            angle,
            speed,
            accel,
            self._veh.data,
            vrow,
            self._per.data,
            prow,
            self._per.speeds,
            time,
            self._before,
            self._dt,
        )
        lanes = [*veh.lane, *per.lane]
        edges = list(map(self._edge_of.get, lanes))
        if None in edges:
            edges = [
                e if e is not None else self._edge(ln) for e, ln in zip(edges, lanes, strict=True)
            ]
        return WorldState(
            time=time,
            ids=np.array([*veh.ids, *per.ids], dtype=object),
            cls=st[:, 0].astype(np.int8),
            xyz=xyz,
            heading=heading,
            speed=speed,
            accel=accel,
            length=st[:, 1],
            width=st[:, 2],
            height=st[:, 3],
            lane=np.array(lanes, dtype=object),
            edge=np.array(edges, dtype=object),
        )

    def _edge(self, lane: str) -> str:
        # a SUMO lane id is '<edge id>_<index>'
        edge = lane.rpartition("_")[0]
        self._edge_of[lane] = edge
        return edge

    def _read_getters(self) -> tuple[Columns, Columns]:
        ids, pos, ang, spd, acc, lane = self._v
        vids = list(ids())
        veh = Columns(
            vids,
            positions(pos, vids),
            list(map(ang, vids)),
            list(map(spd, vids)),
            list(map(acc, vids)),
            list(map(lane, vids)),
        )
        ids, pos, ang, spd, lane = self._p
        pids = list(ids())
        per = Columns(
            pids,
            positions(pos, pids),
            list(map(ang, pids)),
            list(map(spd, pids)),
            None,
            list(map(lane, pids)),
        )
        return veh, per

    def _read_subscriptions(self) -> tuple[Columns, Columns]:
        s = self._sumo
        tc = s.constants
        dep = s.simulation.getSubscriptionResults()
        for vid in dep.get(tc.VAR_DEPARTED_VEHICLES_IDS, ()):
            s.vehicle.subscribe(vid, self._veh_vars)
        for pid in dep.get(tc.VAR_DEPARTED_PERSONS_IDS, ()):
            s.person.subscribe(pid, self._per_vars)
        # actors are listed from getIDList so both read paths give the same order
        vids = list(s.vehicle.getIDList())
        pids = list(s.person.getIDList())
        vres = s.vehicle.getAllSubscriptionResults()
        pres = s.person.getAllSubscriptionResults()
        vr = [vres.get(i) or self._fetch(self._v, self._veh_vars, i) for i in vids]
        pr = [pres.get(i) or self._fetch(self._p, self._per_vars, i) for i in pids]
        vc = [[r[k] for r in vr] for k in self._veh_vars]
        pc = [[r[k] for r in pr] for k in self._per_vars]
        veh = Columns(vids, _xyz(vc[0]), *vc[1:])
        return veh, Columns(pids, _xyz(pc[0]), pc[1], pc[2], None, pc[3])

    @staticmethod
    def _fetch(
        getters: Sequence[Callable[[str], object]], keys: Sequence[str], actor_id: str
    ) -> dict:
        return dict(zip(keys, (g(actor_id) for g in getters[1:]), strict=True))


def _xyz(points: list[tuple[float, float, float]]) -> np.ndarray:
    return np.array(points, dtype=float).reshape(len(points), 3)
