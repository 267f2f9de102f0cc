"""Read one WorldState per step out of a running libsumo simulation.

Two read paths give identical states. ``"getters"`` calls libsumo's per-object getters in one
pass; ``"subscriptions"`` subscribes each actor to its variables at departure and fetches all
results with one ``getAllSubscriptionResults`` call per domain. In libsumo (in-process, no
socket) the getters are the faster of the two (benchmarks/worldstate.py measures both), so
they are the default. Static attributes (class, size) are read once per actor and cached.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from hiyari.traffic.actor_class import ActorClass, actor_class_from_vclass
from hiyari.traffic.world_state import WorldState

ReadMode = Literal["getters", "subscriptions"]


@dataclass
class _Static:
    cls: list[int] = field(default_factory=list)
    length: list[float] = field(default_factory=list)
    width: list[float] = field(default_factory=list)
    height: list[float] = field(default_factory=list)


class WorldStateReader:
    """Turns the current libsumo state into a WorldState; one reader per simulation."""

    def __init__(self, sumo, mode: ReadMode = "getters") -> None:
        if mode not in ("getters", "subscriptions"):
            raise ValueError(f"unknown read mode {mode!r} (getters or subscriptions)")
        self._sumo = sumo
        self._mode = mode
        self._static: dict[str, tuple[int, float, float, float]] = {}
        self._prev_speed: dict[str, float] = {}
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

    def _static_of(self, domain, actor_id: str, is_person: bool) -> tuple[int, float, float, float]:
        info = self._static.get(actor_id)
        if info is None:
            cls = (
                ActorClass.PEDESTRIAN
                if is_person
                else actor_class_from_vclass(domain.getVehicleClass(actor_id))
            )
            info = (
                int(cls),
                domain.getLength(actor_id),
                domain.getWidth(actor_id),
                domain.getHeight(actor_id),
            )
            self._static[actor_id] = info
        return info

    def read(self) -> WorldState:
        """The WorldState at the simulation's current time."""
        s = self._sumo
        time = s.simulation.getTime()
        if self._mode == "subscriptions":
            veh_ids, veh_rows, per_ids, per_rows = self._read_subscriptions()
        else:
            veh_ids, veh_rows, per_ids, per_rows = self._read_getters()
        ids = veh_ids + per_ids
        n, nv = len(ids), len(veh_ids)
        static = [self._static_of(s.vehicle, i, False) for i in veh_ids]
        static += [self._static_of(s.person, i, True) for i in per_ids]
        st = np.array(static, dtype=np.float64).reshape(n, 4)
        pos = np.array(veh_rows[0] + per_rows[0], dtype=np.float64).reshape(n, 3)
        angle = np.array(veh_rows[1] + per_rows[1], dtype=np.float64)
        speed = np.array(veh_rows[2] + per_rows[2], dtype=np.float64)
        accel = np.zeros(n)
        accel[:nv] = veh_rows[3]
        # persons have no acceleration getter: difference of speeds over the last step
        dt = s.simulation.getDeltaT()
        prev = self._prev_speed
        for k, pid in enumerate(per_ids, start=nv):
            accel[k] = (speed[k] - prev.get(pid, speed[k])) / dt
        self._prev_speed = dict(zip(per_ids, speed[nv:].tolist(), strict=True))

        heading = np.radians(90.0 - angle)
        heading = np.arctan2(np.sin(heading), np.cos(heading))
        lanes = veh_rows[4] + per_rows[4]
        length = st[:, 1]
        xyz = pos.copy()
        # SUMO reports the front-bumper centre; the toolkit uses the rectangle centre
        xyz[:, 0] -= 0.5 * length * np.cos(heading)
        xyz[:, 1] -= 0.5 * length * np.sin(heading)
        return WorldState(
            time=time,
            ids=np.array(ids, dtype=object),
            cls=st[:, 0].astype(np.int8),
            xyz=xyz,
            heading=heading,
            speed=speed,
            accel=accel,
            length=length,
            width=st[:, 2],
            height=st[:, 3],
            lane=np.array(lanes, dtype=object),
            # a SUMO lane id is '<edge id>_<index>'
            edge=np.array([ln.rpartition("_")[0] for ln in lanes], dtype=object),
        )

    def _read_getters(self):
        v, p = self._sumo.vehicle, self._sumo.person
        vids = list(v.getIDList())
        pids = list(p.getIDList())
        veh = (
            [v.getPosition3D(i) for i in vids],
            [v.getAngle(i) for i in vids],
            [v.getSpeed(i) for i in vids],
            [v.getAcceleration(i) for i in vids],
            [v.getLaneID(i) for i in vids],
        )
        per = (
            [p.getPosition3D(i) for i in pids],
            [p.getAngle(i) for i in pids],
            [p.getSpeed(i) for i in pids],
            None,
            [p.getLaneID(i) for i in pids],
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
        # subscriptions of actors that departed this very step fill in on the next step, so
        # actors are listed from getIDList to keep both read paths identical
        vids = list(s.vehicle.getIDList())
        pids = list(s.person.getIDList())
        vres = s.vehicle.getAllSubscriptionResults()
        pres = s.person.getAllSubscriptionResults()
        vr = [vres.get(i) or self._fetch_vehicle(i) for i in vids]
        pr = [pres.get(i) or self._fetch_person(i) for i in pids]
        veh = tuple([r[k] for r in vr] for k in self._veh_vars)
        per_cols = [[r[k] for r in pr] for k in self._per_vars]
        per = (per_cols[0], per_cols[1], per_cols[2], None, per_cols[3])
        return vids, veh, pids, per

    def _fetch_vehicle(self, vid: str) -> dict:
        v = self._sumo.vehicle
        vals = (
            v.getPosition3D(vid),
            v.getAngle(vid),
            v.getSpeed(vid),
            v.getAcceleration(vid),
            v.getLaneID(vid),
        )
        return dict(zip(self._veh_vars, vals, strict=True))

    def _fetch_person(self, pid: str) -> dict:
        p = self._sumo.person
        vals = (p.getPosition3D(pid), p.getAngle(pid), p.getSpeed(pid), p.getLaneID(pid))
        return dict(zip(self._per_vars, vals, strict=True))
