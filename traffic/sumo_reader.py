"""Read one WorldState per step out of a running libsumo simulation.

Two read paths give identical states. ``"getters"`` calls libsumo's per-object getters in one
pass; ``"subscriptions"`` subscribes each actor to its variables at departure and fetches all
results with one ``getAllSubscriptionResults`` call per domain. In libsumo (in-process, no
socket) the getters are the faster of the two (benchmarks/worldstate.py measures both: the
subscription path also makes every simulation step slower), so they are the default.
Static attributes (class, size) are read once per actor and kept in arrays.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from itertools import chain
from types import ModuleType
from typing import Literal

import numpy as np

from hiyari.kinematics import point_ahead, wrap_angle
from hiyari.traffic.actor_class import ActorClass, actor_class_from_vclass
from hiyari.traffic.world_state import WorldState

ReadMode = Literal["getters", "subscriptions"]


class _StaticTable:
    """Per-actor class and size, appended when an actor is first seen."""

    def __init__(self) -> None:
        self.row: dict[str, int] = {}
        self.data = np.zeros((64, 4))  # cls, length, width, height
        self.prev_speed = np.zeros(64)

    def rows(
        self, ids: list[str], fetch: Callable[[str], tuple[float, float, float, float]]
    ) -> np.ndarray:
        get = self.row.get
        idx = [get(i, -1) for i in ids]
        if -1 in idx:
            for k, i in enumerate(ids):
                if idx[k] < 0:
                    idx[k] = self._add(i, fetch(i))
        return np.array(idx, dtype=np.intp)

    def _add(self, actor_id: str, values: tuple[float, float, float, float]) -> int:
        r = len(self.row)
        if r == len(self.data):
            self.data = np.concatenate([self.data, np.zeros_like(self.data)])
            self.prev_speed = np.concatenate([self.prev_speed, np.zeros_like(self.prev_speed)])
        self.data[r] = values
        self.prev_speed[r] = np.nan
        self.row[actor_id] = r
        return r


class WorldStateReader:
    """Turns the current libsumo state into a WorldState; one reader per simulation."""

    def __init__(self, sumo: ModuleType, mode: ReadMode = "getters") -> None:
        if mode not in ("getters", "subscriptions"):
            raise ValueError(f"unknown read mode {mode!r} (getters or subscriptions)")
        self._sumo = sumo
        self._mode = mode
        self._veh = _StaticTable()
        self._per = _StaticTable()
        self._edge_of: dict[str, str] = {}
        # the SWIG functions themselves: libsumo's Python wrappers add a call layer per value
        c = sumo._libsumo
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
            sumo.simulation.subscribe([tc.VAR_DEPARTED_VEHICLES_IDS, tc.VAR_DEPARTED_PERSONS_IDS])

    def _vehicle_static(self, vid: str) -> tuple[float, float, float, float]:
        v = self._sumo.vehicle
        vclass = v.getVehicleClass(vid)
        # permission-free scripted actors (vClass "ignoring") say what they are by their shape
        cls = actor_class_from_vclass(v.getShapeClass(vid) if vclass == "ignoring" else vclass)
        return float(cls), v.getLength(vid), v.getWidth(vid), v.getHeight(vid)

    def _person_static(self, pid: str) -> tuple[float, float, float, float]:
        p = self._sumo.person
        return float(ActorClass.PEDESTRIAN), p.getLength(pid), p.getWidth(pid), p.getHeight(pid)

    def read(self) -> WorldState:
        """The WorldState at the simulation's current time."""
        s = self._sumo
        time = s.simulation.getTime()
        if self._mode == "subscriptions":
            vids, vcols, pids, pcols = self._read_subscriptions()
        else:
            vids, vcols, pids, pcols = self._read_getters()
        nv, n = len(vids), len(vids) + len(pids)
        vrow = self._veh.rows(vids, self._vehicle_static)
        prow = self._per.rows(pids, self._person_static)
        st = np.concatenate([self._veh.data[vrow], self._per.data[prow]])
        pos = np.fromiter(chain.from_iterable(vcols[0] + pcols[0]), float, 3 * n).reshape(n, 3)
        angle = np.fromiter(chain(vcols[1], pcols[1]), float, n)
        speed = np.fromiter(chain(vcols[2], pcols[2]), float, n)
        accel = np.empty(n)
        accel[:nv] = vcols[3]
        # persons have no acceleration getter: difference of speeds over the last step
        prev = self._per.prev_speed[prow]
        pspeed = speed[nv:]
        accel[nv:] = np.where(np.isnan(prev), 0.0, (pspeed - prev) / s.simulation.getDeltaT())
        self._per.prev_speed[prow] = pspeed

        heading = wrap_angle(np.radians(90.0 - angle))
        length = st[:, 1]
        # SUMO reports the front-bumper centre; the toolkit uses the rectangle centre
        pos[:, :2] = point_ahead(pos[:, :2], heading, -0.5 * length)
        lanes = vcols[4] + pcols[4]
        edge_of = self._edge_of
        edges = [edge_of.get(ln) or self._edge(ln) for ln in lanes]
        return WorldState(
            time=time,
            ids=np.array(vids + pids, dtype=object),
            cls=st[:, 0].astype(np.int8),
            xyz=pos,
            heading=heading,
            speed=speed,
            accel=accel,
            length=length,
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

    def _read_getters(self):
        ids, pos, ang, spd, acc, lane = self._v
        vids = list(ids())
        veh = (
            [pos(i) for i in vids],
            [ang(i) for i in vids],
            [spd(i) for i in vids],
            [acc(i) for i in vids],
            [lane(i) for i in vids],
        )
        ids, pos, ang, spd, lane = self._p
        pids = list(ids())
        per = (
            [pos(i) for i in pids],
            [ang(i) for i in pids],
            [spd(i) for i in pids],
            None,
            [lane(i) for i in pids],
        )
        return vids, veh, pids, per

    def _read_subscriptions(self):
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
        veh = tuple([r[k] for r in vr] for k in self._veh_vars)
        pc = [[r[k] for r in pr] for k in self._per_vars]
        return vids, veh, pids, (pc[0], pc[1], pc[2], None, pc[3])

    @staticmethod
    def _fetch(
        getters: Sequence[Callable[[str], object]], keys: Sequence[str], actor_id: str
    ) -> dict:
        return dict(zip(keys, (g(actor_id) for g in getters[1:]), strict=True))
