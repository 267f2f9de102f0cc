"""Traffic actions as real SUMO traffic: sources insert SUMO-driven vehicles (their own driver
models, routes ahead along the net), sinks take them out, a swarm keeps a number of them around
an entity; TrafficStopAction ends one by its name. The scenario's entities are never touched.

Random choices (where along a lane, which vehicle of the mix, which speed) come from one
generator per action seeded from its name, so a run repeats bit for bit.
"""

from __future__ import annotations

import math
import zlib
from typing import TYPE_CHECKING

import numpy as np

from hiyari.bridge.openscenario.model.global_actions import (
    TrafficAreaAction,
    TrafficMix,
    TrafficSinkAction,
    TrafficSourceAction,
    TrafficSwarmAction,
)
from hiyari.traffic.actor_class import CLASS_SIZE, ActorClass
from hiyari.traffic.commands import VehicleType
from hiyari.traffic.simulation import Simulation
from hiyari.traffic.world_state import WorldState

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine

#: Spacing of the candidate spots along lanes where a swarm inserts, m.
SPOT_STEP = 5.0
#: OpenSCENARIO vehicle categories -> (SUMO vClass, hiyari actor class).
_CATEGORY = {
    "car": ("passenger", ActorClass.CAR),
    "van": ("passenger", ActorClass.CAR),
    "truck": ("truck", ActorClass.TRUCK),
    "trailer": ("truck", ActorClass.TRUCK),
    "semitrailer": ("truck", ActorClass.TRUCK),
    "bus": ("bus", ActorClass.BUS),
    "motorbike": ("motorcycle", ActorClass.MOTORCYCLE),
    "bicycle": ("bicycle", ActorClass.BICYCLE),
    "tram": ("bus", ActorClass.BUS),
    "train": ("bus", ActorClass.BUS),
}


class _Traffic:
    """What every traffic action keeps: its name, generator and the vehicles it inserted."""

    def __init__(self, name: str, mix: TrafficMix | None) -> None:
        self.name = name
        self.rng = np.random.default_rng(zlib.crc32(name.encode()))
        self.mix = mix
        self.ids: list[str] = []

    def _insert(
        self, engine: ScenarioEngine, sim: Simulation, lane: object, pos: float, speed: float
    ) -> None:
        w = np.array([e[0] for e in self.mix.entries])
        weight, cat, length, width, height = self.mix.entries[
            int(self.rng.choice(len(w), p=w / w.sum()))
        ]
        vclass, cls = _CATEGORY.get(cat, ("passenger", ActorClass.CAR))
        size = CLASS_SIZE[cls]
        type_id = f"hiyari_traffic_{cat}_{length}_{width}_{height}"
        if type_id not in engine._types:
            engine._types.add(type_id)
            sim.define_vehicle_type(
                VehicleType(type_id, length or size.length, width or size.width,
                            height or size.height, vclass=vclass)
            )  # fmt: skip
        vid = f"{self.name or 'traffic'}#{engine.traffic_count}"
        engine.traffic_count += 1
        route = engine.roads.route_from(lane.edge)
        sim.add_vehicle(vid, route, type_id, lane.index, pos, speed, scripted=False)
        self.ids.append(vid)


class Source(_Traffic):
    """A TrafficSourceAction running."""

    def __init__(self, engine: ScenarioEngine, b: TrafficSourceAction) -> None:
        super().__init__(b.name, b.mix)
        self.b, self.t0, self.made = b, engine.now, 0
        p = engine.resolver.resolve(b.position)
        self.lane = engine.roads.sumo_lane(p.road, p.lane, p.s) if p.road else None
        self.pos = 0.0 if self.lane is None else engine.roads.place(p.road, p.lane, p.s).pos

    def update(self, engine: ScenarioEngine, sim: Simulation, world: WorldState) -> None:
        if self.lane is None:
            return
        due = math.floor(self.b.rate * (engine.now - self.t0) + 1e-9)  # the rate exactly
        while self.made < due:
            self.made += 1
            pos = float(np.clip(self.pos + self.rng.uniform(-self.b.radius, self.b.radius), 0.0,
                                self.lane.length))  # fmt: skip
            speed = self.b.speed if self.b.speed is not None else sim.lane_speed(self.lane.id)
            self._insert(engine, sim, self.lane, pos, speed)


class Sink(_Traffic):
    """A TrafficSinkAction running."""

    def __init__(self, engine: ScenarioEngine, b: TrafficSinkAction) -> None:
        super().__init__(b.name, None)
        self.b, self.due = b, 0.0
        p = engine.resolver.resolve(b.position)
        self.xy = np.array([p.x, p.y])

    def update(self, engine: ScenarioEngine, sim: Simulation, world: WorldState) -> None:
        near = np.hypot(*(world.xyz[:, :2] - self.xy).T) <= self.b.radius
        ids = [i for i in world.ids[near].tolist() if i not in engine.index]
        if self.b.rate is not None:
            self.due += self.b.rate * engine.dt
            ids = ids[: int(self.due)]
            self.due -= len(ids)
        for vid in ids:
            sim.remove_actor(vid, bool(world.is_pedestrian[world.index(vid)]))


class Swarm(_Traffic):
    """A TrafficSwarmAction running."""

    def __init__(self, engine: ScenarioEngine, b: TrafficSwarmAction) -> None:
        super().__init__(b.name, b.mix)
        self.b = b
        self.seen: set[str] = set()

    def _inside(self, engine: ScenarioEngine, xy: np.ndarray) -> np.ndarray:
        c = engine.pose_of(self.b.central)
        ch, sh = math.cos(c.h), math.sin(c.h)
        rel = xy - np.array([c.x, c.y])
        along, across = rel @ np.array([ch, sh]), rel @ np.array([-sh, ch])
        ellipse = ((along - self.b.offset) / self.b.semi_major) ** 2 + (
            across / self.b.semi_minor
        ) ** 2
        return (ellipse <= 1.0) & (np.hypot(along, across) >= self.b.inner_radius)

    def update(self, engine: ScenarioEngine, sim: Simulation, world: WorldState) -> None:
        present = set(world.ids.tolist())
        self.seen |= present & set(self.ids)
        here = [i for i in self.ids if i in present]
        waiting = [i for i in self.ids if i not in self.seen]  # SUMO inserts them yet
        if here:
            out = ~self._inside(engine, world.xyz[world.rows(here), :2])
            for vid in np.array(here)[out].tolist():
                sim.remove_actor(vid)
            here = [v for v, o in zip(here, out.tolist(), strict=True) if not o]
        self.ids = here + waiting
        for _ in range(self.b.count - len(self.ids)):
            spot = self._spot(engine, sim)
            if spot is None:
                return
            lane, pos = spot
            lo, hi = self.b.speed_range or (sim.lane_speed(lane.id),) * 2
            self._insert(engine, sim, lane, pos, float(self.rng.uniform(lo, hi)))

    def _spot(self, engine: ScenarioEngine, sim: Simulation) -> tuple[object, float] | None:
        """A car lane and position inside the ring (the central entity's way of travel with
        the weight ``same``), drawn among the lanes' points every SPOT_STEP m; None when there
        is none."""
        c = engine.pose_of(self.b.central)
        same = self.rng.uniform(0.0, self.b.same + self.b.opposite) < self.b.same
        spots = []
        for lane in engine.roads.lanes():
            if lane.length < 2 * SPOT_STEP or not sim.lane_allows(lane.id, "passenger"):
                continue
            s = np.arange(SPOT_STEP, lane.length - SPOT_STEP, SPOT_STEP)
            xy = _along(lane, s)
            seg = np.clip(np.searchsorted(lane.cum, s) - 1, 0, len(lane.shape) - 2)
            d = lane.shape[seg + 1] - lane.shape[seg]
            with_it = np.cos(np.arctan2(d[:, 1], d[:, 0]) - c.h) > 0
            ok = self._inside(engine, xy) & (with_it == same)
            spots += [(lane, float(x)) for x in s[ok].tolist()]
        if not spots:
            return None
        return spots[int(self.rng.integers(len(spots)))]


class Area(_Traffic):
    """A TrafficAreaAction running: its spots (lane, position) every SPOT_STEP m on the car
    lanes of the area, found once."""

    def __init__(self, engine: ScenarioEngine, b: TrafficAreaAction) -> None:
        super().__init__(b.name, b.mix)
        self.b, self.filled = b, False
        self.seen: set[str] = set()
        self.spots: list[tuple[object, float]] | None = None
        self.xy = np.zeros((0, 2))

    def _find_spots(self, engine: ScenarioEngine, sim: Simulation) -> None:
        spots: list[tuple[object, float]] = []
        if self.b.polygon:
            poly = np.array([[p.x, p.y] for p in map(engine.resolver.resolve, self.b.polygon)])
            for lane in engine.roads.lanes():
                if lane.length < 2 * SPOT_STEP or not sim.lane_allows(lane.id, "passenger"):
                    continue
                s = np.arange(SPOT_STEP, lane.length - SPOT_STEP, SPOT_STEP)
                xy = _along(lane, s)
                spots += [(lane, float(x)) for x in s[_in_polygon(xy, poly)].tolist()]
        for road, s0, s1, lanes in self.b.ranges:
            rd = engine.roads.odr.road(road)
            ids = lanes or tuple(
                k for k, spec in rd.sections[rd.section_at(min(s0, rd.length))].lanes.items()
                if k != 0 and spec.type == "driving"
            )  # fmt: skip
            for s in np.arange(max(min(s0, s1), 0.0), min(max(s0, s1), rd.length), SPOT_STEP):
                for lane_id in ids:
                    ln = engine.roads.sumo_lane(road, lane_id, float(s))
                    if ln is not None and sim.lane_allows(ln.id, "passenger"):
                        spots.append((ln, engine.roads.place(road, lane_id, float(s)).pos))
        self.spots = spots
        self.xy = np.array([_along(ln, np.array([p]))[0] for ln, p in spots]).reshape(-1, 2)

    def update(self, engine: ScenarioEngine, sim: Simulation, world: WorldState) -> None:
        if self.spots is None:
            self._find_spots(engine, sim)
        if not self.spots or (self.filled and not self.b.continuous):
            return
        present = set(world.ids.tolist())
        self.seen |= present & set(self.ids)
        here = [i for i in self.ids if i in present]
        inside = 0
        if here:
            pts = world.xyz[world.rows(here), :2]
            near = np.min(np.hypot(*(pts[:, None, :] - self.xy[None]).transpose(2, 0, 1)), axis=1)
            inside = int((near <= SPOT_STEP).sum())
        waiting = sum(1 for i in self.ids if i not in self.seen)  # SUMO inserts them yet
        for _ in range(self.b.count - inside - waiting):
            lane, pos = self.spots[int(self.rng.integers(len(self.spots)))]
            self._insert(engine, sim, lane, pos, sim.lane_speed(lane.id))
        self.filled = True


def _along(lane: object, s: np.ndarray) -> np.ndarray:
    """World x, y (n, 2) at ``s`` m along a SUMO lane's shape."""
    return np.column_stack(
        [np.interp(s, lane.cum, lane.shape[:, 0]), np.interp(s, lane.cum, lane.shape[:, 1])]
    )


def _in_polygon(xy: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """(n,) whether each point lies inside the polygon (even-odd rule)."""
    inside = np.zeros(len(xy), dtype=bool)
    x, y = xy[:, 0], xy[:, 1]
    for (x0, y0), (x1, y1) in zip(poly, np.roll(poly, -1, axis=0), strict=True):
        crosses = (y0 > y) != (y1 > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            at = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
        inside ^= crosses & (x < at)
    return inside
