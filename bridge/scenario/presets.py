"""Scenario scripts on the generated roads: JAMA / UN R157 cut-in, cut-out and deceleration
(other vehicles moved exactly as Annex G defines), the DIVP / Euro NCAP CPNC-50 pedestrian
dart-out from behind a parked car, a car-to-stationary-car approach, and free city driving.

A concrete scenario's file parameters (km/h, g as written) become its type's frozen dataclass
of SI parameters once (``typed_parameters``); ``BUILDERS`` maps each parameter class to its
builder (the one registry). Each builder returns a ``Scenario``: the files SUMO loads, and
hooks that insert the ego and the scripted actors and move them every step. Road coordinates: ``s`` along the ego lane's
centre line, ``d`` to its left (metres). Script time 0 is the start of the manoeuvre; the run
starts ``lead_in`` seconds earlier so that tracks are established.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiyari.bridge.scenario.closed_loop import ScenarioHooks
from hiyari.bridge.scenario.toml_file import ConcreteScenario
from hiyari.bridge.scenario.warm import WarmCache
from hiyari.errors import HiyariError
from hiyari.kinematics import Pose
from hiyari.net.road.lane_frame import RoadFrame
from hiyari.net.road.network import RoadNetwork
from hiyari.net.sumo.build import (
    CityGridParams,
    IntersectionParams,
    R157RoadParams,
    build_city_grid,
    build_intersection,
    build_r157_road,
)
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.commands import VehicleType
from hiyari.traffic.demand import DemandConfig, write_demand
from hiyari.traffic.manoeuvres import ScriptedPerson, ScriptedVehicle
from hiyari.traffic.simulation import Simulation
from hiyari.traffic.world_state import WorldState
from hiyari.units import G, kmh_to_mps


@dataclass(frozen=True)
class ActorSizes:
    """Vehicle and pedestrian dimensions (m), scenario parameters. Annex G: other vehicles
    1.9 m x 5.3 m; the ego 1.9 m x 4.8 m (MODELS.md §1); both a car's default height
    (ActorClass.CAR.size); CPNC child dummy about 1.15 m tall."""

    ego_length: float = 4.8
    ego_width: float = 1.9
    ego_height: float = ActorClass.CAR.size.height
    other_length: float = 5.3
    other_width: float = 1.9
    other_height: float = ActorClass.CAR.size.height
    child_width: float = 0.5
    child_depth: float = 0.3
    child_height: float = 1.15


@dataclass(frozen=True)
class ScenarioConstants:
    """Fixed scenario choices (MODELS.md §1 and the toolkit's own where the seeds are silent)."""

    lane_width: float = 3.5
    follow_thw: float = 2.0  # s, ego to lead in cut-out and deceleration (JAMA)
    lead_in: float = 1.5  # s before the manoeuvre starts
    ego_start_s: float = 20.0  # m, ego front position on the road at the start of the run
    parked_gap_to_path: float = 0.5  # m, parked car front to the pedestrian's path
    kerb_offset: float = 1.0  # m, parked car centre beyond the lane's right edge
    ped_start_beyond_lane: float = 2.0  # m, child start from the lane's right edge
    settle_after_stop: float = 1.0  # s the run continues once the ego has stopped
    city_speed_mode: int = 24  # SUMO respects lights and right of way; safety is the stack's


@dataclass
class Scenario(ScenarioHooks):
    """A ready-to-run scripted scenario."""

    net: Path = Path()
    network: RoadNetwork | None = None  # the net read once, shared by everything in the run
    ego_id: str = "ego"
    target_id: str = ""
    conflict_point: tuple[float, float] | None = None
    routes: list[Path] = field(default_factory=list)
    ego_route: list[str] = field(default_factory=list)
    ego_lane: int = 0
    ego_start_s: float = 0.0
    ego_speed: float = 0.0
    ego_speed_mode: int = 0
    scripted: list = field(default_factory=list)
    lead_in: float = 0.0
    warmup: float = 0.0  # s of traffic before the ego enters
    start_time: float = 0.0
    settle_after_stop: float = 1.0
    sizes: ActorSizes = field(default_factory=ActorSizes)
    _stopped_at: float = float("nan")

    def insert(self, sim: Simulation) -> None:
        """Create vehicle types, the ego and the scripted actors (at sim.time)."""
        z = self.sizes
        sim.define_vehicle_type(
            VehicleType("ego", z.ego_length, z.ego_width, z.ego_height, max_speed=70.0)
        )
        sim.define_vehicle_type(
            VehicleType("other", z.other_length, z.other_width, z.other_height, max_speed=70.0)
        )
        sim.define_vehicle_type(
            VehicleType(
                "child", z.child_depth, z.child_width, z.child_height, base="DEFAULT_PEDTYPE"
            )
        )
        sim.add_vehicle(
            self.ego_id,
            self.ego_route,
            "ego",
            self.ego_lane,
            self.ego_start_s,
            self.ego_speed,
            scripted=True,
        )
        sim.set_speed_mode(self.ego_id, self.ego_speed_mode)
        for actor in self.scripted:
            if isinstance(actor, ScriptedVehicle):
                sim.add_vehicle(
                    actor.vid,
                    [actor.frame.edge],
                    "other",
                    actor.frame.lane_index,
                    1.0,
                    0.0,
                    scripted=True,
                )
            else:
                sim.add_person(actor.pid, actor.frame.edge, 1.0, "child", wait=3600.0)
        self.start_time = sim.time

    def script_time(self, sim_time: float) -> float:
        return sim_time - self.start_time - self.lead_in

    def before_step(self, sim: Simulation, script_time: float) -> None:
        for actor in self.scripted:
            actor.place(sim, script_time)

    def done(self, world: WorldState, ego: Pose, script_time: float) -> bool:
        """Ends ``settle_after_stop`` seconds after the ego first comes to a standstill."""
        if ego.speed < 0.05 and script_time > 0 and not np.isfinite(self._stopped_at):
            self._stopped_at = script_time
        return script_time - self._stopped_at >= self.settle_after_stop


def _road_lanes(network: RoadNetwork) -> tuple[RoadFrame, RoadFrame, list[str]]:
    """Right (ego) and left lane frames of the two-lane R157 road, and the ego route."""
    n = network.sumo
    edges = [e for e in n.getEdges() if not e.isSpecial() and e.getLaneNumber() >= 2]
    if not edges:
        raise HiyariError(f"{network.path}: no two-lane edge for the R157 scenarios")
    edge = max(edges, key=lambda e: e.getLength())
    right, left = edge.getLane(0), edge.getLane(1)
    return (
        network.lane_frame(right.getID()),
        network.lane_frame(left.getID()),
        [edge.getID()],
    )


def _const_speed(s0: float, v: float, d: float = 0.0):
    return lambda t: (s0 + v * t, d, v, 0.0)


@dataclass(frozen=True)
class CutIn:
    """Annex G cut-in: ego speed ``ve0`` and the other car's ``vo0`` (m/s), its front gap
    ``dx0`` ahead of the ego's front at the start of the manoeuvre (m), lateral speed ``vy``
    (m/s)."""

    ve0: float
    vo0: float
    dx0: float
    vy: float


@dataclass(frozen=True)
class CutOut:
    """Annex G cut-out: ego and lead at ``ve0`` (m/s), the lead leaves at lateral speed
    ``vy`` (m/s) revealing a stopped car ``dx0_f`` m ahead of it."""

    ve0: float
    vy: float
    dx0_f: float


@dataclass(frozen=True)
class Decel:
    """Annex G deceleration: ego and lead at ``ve0`` (m/s), the lead brakes at ``decel``
    (m/s^2) to a standstill."""

    ve0: float
    decel: float


@dataclass(frozen=True)
class Stationary:
    """Approach at ``ve0`` (m/s) to a car standing ``gap`` m ahead of the ego's front."""

    ve0: float
    gap: float


@dataclass(frozen=True)
class DartOut:
    """CPNC dart-out: ego at ``ve0``, child at ``ped_speed`` (m/s), timed to meet the ego's
    front at ``impact_fraction`` of its width from the right; ``parked_car``: it steps out
    from behind one."""

    ve0: float
    ped_speed: float
    impact_fraction: float
    parked_car: bool


@dataclass(frozen=True)
class City:
    """Free driving at ``ve0`` (m/s) in a generated city with SUMO traffic (vehicles and
    persons per hour) after ``warmup`` s."""

    ve0: float
    vehicles_per_hour: float
    persons_per_hour: float
    warmup: float


def _ve0(p: dict[str, float]) -> float:
    return kmh_to_mps(p.get("ve0_kmh", 0.0))


#: File parameters (the names in PARAMETERS, km/h and g as written) -> the typed SI parameters.
_TYPED = {
    "cut-in": lambda p: CutIn(_ve0(p), kmh_to_mps(p["vo0_kmh"]), p["dx0_m"], p["vy_ms"]),
    "cut-out": lambda p: CutOut(_ve0(p), p["vy_ms"], p["dx0_f_m"]),
    "decel": lambda p: Decel(_ve0(p), p["gx_max_g"] * G),
    "stationary": lambda p: Stationary(_ve0(p), p["gap_m"]),
    "dart-out": lambda p: DartOut(
        _ve0(p),
        kmh_to_mps(p["ped_speed_kmh"]),
        p["impact_fraction"],
        p.get("parked_car", 1.0) >= 0.5,
    ),
    "city": lambda p: City(_ve0(p), p["vehicles_per_hour"], p["persons_per_hour"], p["warmup_s"]),
}


def typed_parameters(cs: ConcreteScenario) -> object:
    """The concrete scenario's parameters as its type's SI dataclass (converted once)."""
    if cs.type not in _TYPED:
        raise HiyariError(f"no scenario script for type {cs.type!r}")
    return _TYPED[cs.type](cs.params)


@dataclass(frozen=True)
class _Build:
    """What every builder gets: the run's folder, constants, sizes and seed / duration."""

    workdir: Path
    k: ScenarioConstants
    z: ActorSizes
    seed: int
    duration: float
    roads: WarmCache | None = None  # reuse roads built earlier in this process

    def road(self, name: str, build: Callable[[Path, Any], Path], params: Hashable) -> RoadNetwork:
        """The network ``build(workdir / name, params)`` writes (or the cache's copy)."""
        if self.roads is not None:
            return self.roads.road(name, build, params)
        return RoadNetwork(build(self.workdir / name, params))

    def base(self, ve0: float) -> dict:
        k = self.k
        return dict(
            ego_speed=ve0, lead_in=k.lead_in, settle_after_stop=k.settle_after_stop, sizes=self.z
        )

    def s_front0(self, ve0: float) -> float:
        """Ego front at script time 0 if it holds ``ve0`` through the lead-in."""
        return self.k.ego_start_s + ve0 * self.k.lead_in


def _r157(b: _Build, ve0: float) -> tuple[Scenario, RoadFrame]:
    """The R157 road's Scenario with the ego in the right lane; the right lane's frame."""
    network = b.road("r157.net.xml", build_r157_road, R157RoadParams())
    right, _, route = _road_lanes(network)
    sc = Scenario(
        net=network.path,
        network=network,
        ego_route=route,
        ego_lane=right.lane_index,
        ego_start_s=b.k.ego_start_s,
        target_id="other",
        **b.base(ve0),
    )
    return sc, right


def _cut_in(p: CutIn, b: _Build) -> Scenario:
    sc, right = _r157(b, p.ve0)
    w, vy, vo0 = b.k.lane_width, p.vy, p.vo0
    s_c0 = b.s_front0(p.ve0) + p.dx0 + b.z.other_length / 2

    def cut_in(t: float) -> tuple[float, float, float, float]:
        d = w if t < 0 else max(0.0, w - vy * t)
        vd = -vy if 0 <= t < w / vy else 0.0
        return s_c0 + vo0 * t, d, vo0, vd

    sc.scripted = [ScriptedVehicle("other", right, cut_in, b.z.other_length)]
    return sc


def _cut_out(p: CutOut, b: _Build) -> Scenario:
    sc, right = _r157(b, p.ve0)
    w, vy, ve0, length = b.k.lane_width, p.vy, p.ve0, b.z.other_length
    s_lead0 = b.s_front0(ve0) + b.k.follow_thw * ve0 + length / 2
    s_stop = s_lead0 + length / 2 + p.dx0_f + length / 2

    def cut_out(t: float) -> tuple[float, float, float, float]:
        d = 0.0 if t < 0 else min(w, vy * t)
        vd = vy if 0 <= t < w / vy else 0.0
        return s_lead0 + ve0 * t, d, ve0, vd

    sc.scripted = [
        ScriptedVehicle("lead", right, cut_out, length),
        ScriptedVehicle("other", right, _const_speed(s_stop, 0.0), length),
    ]
    return sc


def _decel(p: Decel, b: _Build) -> Scenario:
    sc, right = _r157(b, p.ve0)
    a, ve0 = p.decel, p.ve0
    s_lead0 = b.s_front0(ve0) + b.k.follow_thw * ve0 + b.z.other_length / 2

    def decel(t: float) -> tuple[float, float, float, float]:
        if t < 0:
            return s_lead0 + ve0 * t, 0.0, ve0, 0.0
        tt = min(t, ve0 / a)
        return s_lead0 + ve0 * tt - a * tt * tt / 2, 0.0, ve0 - a * tt, 0.0

    sc.scripted = [ScriptedVehicle("other", right, decel, b.z.other_length)]
    return sc


def _stationary(p: Stationary, b: _Build) -> Scenario:
    sc, right = _r157(b, p.ve0)
    s_c = b.s_front0(p.ve0) + p.gap + b.z.other_length / 2
    sc.scripted = [ScriptedVehicle("other", right, _const_speed(s_c, 0.0), b.z.other_length)]
    return sc


def _dart_out(p: DartOut, b: _Build) -> Scenario:
    k, z = b.k, b.z
    network = b.road(
        "street.net.xml", build_intersection, IntersectionParams(lane_width=k.lane_width)
    )
    lane = next(ln for ln in network.sumo.getEdge("w_in").getLanes() if ln.allows("passenger"))
    frame = network.lane_frame(lane.getID())
    vp = p.ped_speed
    s_path = frame.length - 30.0  # the child's path crosses 30 m before the junction
    d_start = -(k.lane_width / 2 + k.ped_start_beyond_lane)
    d_impact = -z.ego_width / 2 + p.impact_fraction * z.ego_width
    # without braking, the ego front reaches the path when the child reaches d_impact
    t_hit = (s_path - z.child_depth / 2 - b.s_front0(p.ve0)) / p.ve0
    t_go = t_hit - (d_impact - d_start) / vp

    def child(t: float) -> tuple[float, float, float, float]:
        if t < t_go:
            return s_path, d_start, 0.0, 0.0
        return s_path, d_start + vp * (t - t_go), 0.0, vp

    s_parked = s_path - k.parked_gap_to_path - z.other_length / 2
    d_parked = -(k.lane_width / 2 + k.kerb_offset)
    sc = Scenario(
        net=network.path,
        network=network,
        ego_route=["w_in", "e_out"],
        ego_lane=lane.getIndex(),
        ego_start_s=k.ego_start_s,
        target_id="child",
        **b.base(p.ve0),
    )
    sc.scripted = [ScriptedPerson("child", frame, child)]
    if p.parked_car:
        parked = _const_speed(s_parked, 0.0, d_parked)
        sc.scripted.insert(0, ScriptedVehicle("parked", frame, parked, z.other_length))
    sc.conflict_point = frame.to_xy(s_path, d_impact)[:2]
    return sc


def _city(p: City, b: _Build) -> Scenario:
    net = build_city_grid(b.workdir / "city.net.xml", CityGridParams())
    routes = write_demand(
        net,
        b.workdir / "demand.rou.xml",
        DemandConfig(
            vehicles_per_hour=p.vehicles_per_hour,
            persons_per_hour=p.persons_per_hour,
            end=p.warmup + b.duration + 60.0,
            seed=b.seed,
            vehicle_mix={"car": 0.85, "truck": 0.05, "bus": 0.05, "motorcycle": 0.05},
        ),
    )
    network = RoadNetwork(net)
    ego_route = _long_route(network)
    first = network.sumo.getEdge(ego_route[0])
    lane = next(ln for ln in first.getLanes() if ln.allows("passenger"))
    sc = Scenario(
        net=net,
        network=network,
        routes=[routes],
        ego_route=ego_route,
        ego_lane=lane.getIndex(),
        warmup=p.warmup,
        ego_start_s=5.0,
        ego_speed=p.ve0,
        ego_speed_mode=b.k.city_speed_mode,
        lead_in=0.0,
        sizes=b.z,
    )
    sc.settle_after_stop = math.inf
    return sc


#: The scenario types: typed parameters -> Scenario (the one registry of builders).
BUILDERS = {
    CutIn: _cut_in,
    CutOut: _cut_out,
    Decel: _decel,
    Stationary: _stationary,
    DartOut: _dart_out,
    City: _city,
}


def build_scenario(
    cs: ConcreteScenario,
    workdir: Path,
    k: ScenarioConstants | None = None,
    sizes: ActorSizes | None = None,
    roads: WarmCache | None = None,
) -> Scenario:
    """The Scenario for one concrete scenario; road files are written into ``workdir``, or
    taken from ``roads`` (built there once per process) when given."""
    params = typed_parameters(cs)
    workdir.mkdir(parents=True, exist_ok=True)
    b = _Build(
        workdir, k or ScenarioConstants(), sizes or ActorSizes(), cs.seed, cs.duration, roads
    )
    return BUILDERS[type(params)](params, b)


def _long_route(network: RoadNetwork) -> list[str]:
    """A long car route across the network: between the most distant boundary edges."""
    n = network.sumo
    cars = [e for e in n.getEdges() if e.allows("passenger") and not e.isSpecial()]
    starts = [e for e in cars if not e.getIncoming()]
    ends = [e for e in cars if not e.getOutgoing()]
    pairs = sorted(
        ((a, b) for a in starts for b in ends if a.getFromNode() is not b.getToNode()),
        key=lambda ab: -math.dist(ab[0].getFromNode().getCoord(), ab[1].getToNode().getCoord()),
    )
    for a, b in pairs:
        path, _ = n.getShortestPath(a, b, vClass="passenger")
        if path:
            return [e.getID() for e in path]
    raise HiyariError(f"{network.path}: no route across the network for the ego")
