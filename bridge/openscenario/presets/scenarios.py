"""The six TOML scenario types as presets of the scenario model: JAMA / UN R157 cut-in,
cut-out and deceleration (other vehicles moved exactly as Annex G defines), the DIVP / Euro
NCAP CPNC-50 pedestrian dart-out from behind a parked car, a car-to-stationary-car approach,
and free city driving.

A concrete scenario's file parameters (km/h, g as written) become its type's frozen dataclass
of SI parameters once (``typed_parameters``); ``BUILDERS`` maps each parameter class to its
builder (the one registry). Each builder returns a ``PresetRun``: a model ``Scenario``
(entities, Init teleports and speeds, events with their triggers and actions) on a generated
SUMO road, which the ScenarioEngine runs exactly as it runs an OpenSCENARIO file, through the
road / lane / s frame of that net (hiyari.net.road.sumo_roads: road = edge, lane 0's centre
line at t = 0). Road coordinates: ``s`` along the ego lane's centre line, ``d`` to its left
(metres). Script time 0 is the start of the manoeuvre; the run starts ``lead_in`` seconds
earlier so that tracks are established.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from hiyari.bridge.openscenario.model.actions import (
    AbsoluteLane,
    AbsoluteSpeed,
    Action,
    AssignRouteAction,
    Dimension,
    FollowTrajectoryAction,
    LaneChangeAction,
    Shape,
    SpeedAction,
    TeleportAction,
    Timing,
    TransitionDynamics,
)
from hiyari.bridge.openscenario.model.conditions import (
    Condition,
    Rule,
    SimulationTimeCondition,
    Trigger,
)
from hiyari.bridge.openscenario.model.entities import ControllerSpec, Entity, EntityKind
from hiyari.bridge.openscenario.model.positions import (
    LanePosition,
    Orientation,
    Position,
    RoadPosition,
)
from hiyari.bridge.openscenario.model.scoring import Scoring
from hiyari.bridge.openscenario.model.storyboard import (
    Act,
    Event,
    InitAction,
    Maneuver,
    ManeuverGroup,
    Scenario,
    Story,
    Storyboard,
)
from hiyari.bridge.openscenario.model.trajectories import Polyline, Trajectory, Vertex
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.errors import HiyariError, about
from hiyari.net.road.buildings import poly_path
from hiyari.net.road.network import RoadNetwork
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.road.sumo_roads import sumo_lane_id, sumo_road_lanes
from hiyari.net.sumo.build import (
    CityGridParams,
    IntersectionParams,
    R157RoadParams,
    build_city_grid,
    build_intersection,
    build_r157_road,
)
from hiyari.net.sumo.files import check_net
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.demand import DemandConfig, write_demand
from hiyari.traffic.sumocfg import SumoScenario, read_sumocfg
from hiyari.units import G, kmh_to_mps

#: Init speeds and positions apply at once.
_STEP = TransitionDynamics(Shape.STEP, Dimension.TIME, 0.0)


@dataclass(frozen=True)
class ActorSizes:
    """Vehicle and pedestrian dimensions (m), scenario parameters. Annex G: other vehicles
    1.9 m x 5.3 m; the ego 1.9 m x 4.8 m (docs/models.md §1); both a car's default height
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
    """Fixed scenario choices (docs/models.md §1 and the toolkit's own where the seeds are silent)."""

    lane_width: float = 3.5
    follow_thw: float = 2.0  # s, ego to lead in cut-out and deceleration (JAMA)
    lead_in: float = 1.5  # s before the manoeuvre starts
    ego_start_s: float = 20.0  # m, ego front position on the road at the start of the run
    parked_gap_to_path: float = 0.5  # m, parked car front to the pedestrian's path
    kerb_offset: float = 1.0  # m, parked car centre beyond the lane's right edge
    ped_start_beyond_lane: float = 2.0  # m, child start from the lane's right edge
    settle_after_stop: float = 1.0  # s the run continues once the ego has stopped
    city_speed_mode: int = 24  # SUMO respects lights and right of way; safety is the stack's


@dataclass(frozen=True)
class World:
    """Where a city run drives instead of the generated grid: a map (``net``, e.g. an
    OpenStreetMap import, with generated demand), or a user's SUMO scenario (``sumo``: its
    own net, demand, additional files and time window; hiyari adds only the ego)."""

    net: Path
    sumo: SumoScenario | None = None

    @staticmethod
    def of_net(path: str | Path) -> World:
        """A map: the SUMO net ``path`` (its buildings from the polygon file beside it)."""
        check_net(path)
        return World(Path(path))

    @staticmethod
    def of_sumocfg(path: str | Path) -> World:
        """A user's SUMO scenario, read from its .sumocfg (one-line HiyariError when broken)."""
        sc = read_sumocfg(path)
        with about(path):  # the net's error says which scenario names it
            check_net(sc.net)
        return World(sc.net, sc)

    def network(self) -> RoadNetwork:
        """The run's road: buildings from the scenario's polygon (additional) files and the
        polygon file beside the net, where there are any."""
        beside = poly_path(self.net)
        polygons = [*(self.sumo.additional if self.sumo else ()), beside]
        return RoadNetwork(self.net, [p for p in dict.fromkeys(polygons) if p.is_file()])


@dataclass(frozen=True)
class PresetRun:
    """A preset ready to run through the ScenarioEngine: the model ``scenario``, its road
    (``network`` and the road / lane / s frame ``roads`` the engine resolves positions in),
    SUMO's own demand files ``routes`` (or the user's scenario ``sumo``) run for ``warmup`` s
    before the scenario starts, and how the run is scored (``scoring``)."""

    scenario: Scenario
    network: RoadNetwork
    roads: RoadLanes
    scoring: Scoring
    routes: tuple[Path, ...] = ()
    warmup: float = 0.0
    sumo: SumoScenario | None = None


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


class RoadCache(Protocol):
    """Roads built once per process and reused (hiyari.bridge.loop.warm.WarmCache is one)."""

    def road(self, name: str, build: Callable[[Path, Any], Path], params: Hashable) -> RoadNetwork:
        """The RoadNetwork of ``build(folder / name, params)``, built on the first call."""
        ...

    def road_lanes(self, network: RoadNetwork) -> RoadLanes:
        """The road / lane / s frame of a generated net, built once."""
        ...


@dataclass(frozen=True)
class _Build:
    """What every builder gets: the run's folder, constants, sizes, seed, duration and step."""

    workdir: Path
    k: ScenarioConstants
    z: ActorSizes
    seed: int
    duration: float
    dt: float
    roads: RoadCache | None = None  # reuse roads built earlier in this process
    world: World | None = None  # city runs: a map or a SUMO scenario instead of the grid

    def road(self, name: str, build: Callable[[Path, Any], Path], params: Hashable) -> RoadNetwork:
        """The network ``build(workdir / name, params)`` writes (or the cache's copy)."""
        if self.roads is not None:
            return self.roads.road(name, build, params)
        return RoadNetwork(build(self.workdir / name, params))

    def lanes(self, network: RoadNetwork) -> RoadLanes:
        """The road / lane / s frame of ``network`` (or the cache's copy)."""
        if self.roads is not None:
            return self.roads.road_lanes(network)
        return sumo_road_lanes(network)

    def s_front0(self, ve0: float) -> float:
        """Ego front at script time 0 if it holds ``ve0`` through the lead-in."""
        return self.k.ego_start_s + ve0 * self.k.lead_in

    def scenario_time(self, script_time: float) -> float:
        """Scenario (engine) time of script time ``script_time``: the engine's time 0 is the
        first state after the insertion step, script time 0 is ``lead_in`` s after the
        insertion."""
        return script_time + self.k.lead_in - self.dt

    def at(self, script_time: float) -> Trigger:
        """A trigger that fires on the state at script time ``script_time`` (on the step grid):
        a transition started there moves its actor from the next state on."""
        return _time_trigger(self.scenario_time(script_time) - 0.5 * self.dt)

    def before(self, script_time: float) -> Trigger:
        """A trigger that fires on the last state before script time ``script_time`` (any
        time): an action timed in scenario time then takes over from the next state on."""
        return _time_trigger(self.scenario_time(script_time) - self.dt - 1e-9)

    def scoring(self, target: str, conflict: tuple[float, float] | None = None) -> Scoring:
        """Gap to ``target``; the run ends ``settle_after_stop`` s after the ego has stopped
        (after script time 0)."""
        return Scoring(target, conflict, self.k.settle_after_stop, self.scenario_time(0.0))

    def entity(self, name: str, who: str) -> Entity:
        """The ego, another car ("other") or the child ("child") with the run's sizes."""
        z = self.z
        if who == "ego":
            return Entity(
                name, EntityKind.VEHICLE, ActorClass.CAR, z.ego_length, z.ego_width, z.ego_height
            )
        if who == "child":
            return Entity(
                name, EntityKind.PEDESTRIAN, ActorClass.PEDESTRIAN,
                z.child_depth, z.child_width, z.child_height,
            )  # fmt: skip
        return Entity(
            name, EntityKind.VEHICLE, ActorClass.CAR, z.other_length, z.other_width, z.other_height
        )


def _time_trigger(after: float) -> Trigger:
    """Fires on the first state later than scenario time ``after`` (s)."""
    return ((Condition("time", SimulationTimeCondition(after, Rule.GREATER_THAN)),),)


def _act(name: str, actor: str, trigger: Trigger, *actions: Action) -> Act:
    """One act with one event of ``actions`` on ``actor``, started by ``trigger``."""
    event = Event(name, actions, trigger)
    group = ManeuverGroup(name, (actor,), (Maneuver(name, (event,)),))
    return Act(name, (group,))


def _place(name: str, pos: Position, speed: float) -> tuple[InitAction, InitAction]:
    """Init actions: ``name`` stands at ``pos`` moving at ``speed`` m/s."""
    return (
        InitAction(name, Action(f"{name} position", TeleportAction(pos))),
        InitAction(name, Action(f"{name} speed", SpeedAction(_STEP, AbsoluteSpeed(speed)))),
    )


def _scenario(
    name: str, entities: list[Entity], init: list[InitAction], acts: list[Act]
) -> Scenario:
    board = Storyboard(tuple(init), (Story(name, tuple(acts)),) if acts else ())
    return Scenario(name, tuple(entities), board, ego="ego")


@dataclass(frozen=True)
class _Road:
    """The R157 road: network, frame, the road (edge) id and the right (ego) and left lanes'
    OpenDRIVE ids."""

    network: RoadNetwork
    roads: RoadLanes
    id: str
    right: int
    left: int


def _r157(b: _Build) -> _Road:
    """The R157 road of this run."""
    network = b.road("r157.net.xml", build_r157_road, R157RoadParams())
    n = network.sumo
    edges = [e for e in n.getEdges() if not e.isSpecial() and e.getLaneNumber() >= 2]
    if not edges:
        raise HiyariError(f"{network.path}: no two-lane edge for the R157 scenarios")
    edge = max(edges, key=lambda e: e.getLength())
    lanes = edge.getLaneNumber()
    right, left = sumo_lane_id(lanes, 0), sumo_lane_id(lanes, 1)
    return _Road(network, b.lanes(network), edge.getID(), right, left)


def _r157_run(
    b: _Build,
    r: _Road,
    ve0: float,
    others: list[Entity],
    init: list[InitAction],
    acts: list[Act],
) -> PresetRun:
    ego_s = b.k.ego_start_s - b.z.ego_length / 2
    init = [*_place("ego", LanePosition(r.id, r.right, ego_s), ve0), *init]
    name = acts[0].name if acts else "stationary"
    sc = _scenario(name, [b.entity("ego", "ego"), *others], init, acts)
    return PresetRun(sc, r.network, r.roads, b.scoring("other"))


def _cut_in(p: CutIn, b: _Build) -> PresetRun:
    r = _r157(b)
    s_c0 = b.s_front0(p.ve0) + p.dx0 + b.z.other_length / 2
    start = b.dt - b.k.lead_in  # script time of the first state
    init = _place("other", RoadPosition(r.id, s_c0 + p.vo0 * start, b.k.lane_width), p.vo0)
    change = LaneChangeAction(
        TransitionDynamics(Shape.LINEAR, Dimension.RATE, p.vy), AbsoluteLane(r.right)
    )
    acts = _sideways("cut-in", "other", change, p.vo0, p.vy, b)
    return _r157_run(b, r, p.ve0, [b.entity("other", "other")], list(init), acts)


def _sideways(
    name: str, actor: str, change: LaneChangeAction, vx: float, vy: float, b: _Build
) -> list[Act]:
    """The acts of an R157 lane change at lateral speed ``vy`` by a car keeping its
    longitudinal speed ``vx`` (Annex 4's tracks give the two components). An OpenSCENARIO
    speed is along the path, so the car drives at hypot(vx, vy) while it moves sideways
    (one lane width) and at ``vx`` again from then on (to within the step the lateral motion
    ends in: its speed is then too high for part of a step, a few millimetres)."""
    faster = SpeedAction(_STEP, AbsoluteSpeed(math.hypot(vx, vy)))
    after = SpeedAction(_STEP, AbsoluteSpeed(vx))
    return [
        _act(name, actor, b.at(0.0), Action(name, change), Action(f"{name} speed", faster)),
        _act(f"{name} end", actor, b.at(b.k.lane_width / vy), Action(f"{name} end", after)),
    ]


def _cut_out(p: CutOut, b: _Build) -> PresetRun:
    r = _r157(b)
    length, ve0 = b.z.other_length, p.ve0
    s_lead0 = b.s_front0(ve0) + b.k.follow_thw * ve0 + length / 2
    s_stop = s_lead0 + length / 2 + p.dx0_f + length / 2
    start = b.dt - b.k.lead_in
    init = [
        *_place("lead", RoadPosition(r.id, s_lead0 + ve0 * start, 0.0), ve0),
        *_place("other", RoadPosition(r.id, s_stop, 0.0), 0.0),
    ]
    # the lead ends lane_width left of the ego lane's centre (the left lane's centre)
    offset = b.k.lane_width - r.roads.odr.road(r.id).lane_t(r.left, 0.0)
    dyn = TransitionDynamics(Shape.LINEAR, Dimension.RATE, p.vy)
    change = LaneChangeAction(dyn, AbsoluteLane(r.left), offset)
    acts = _sideways("cut-out", "lead", change, ve0, p.vy, b)
    others = [b.entity("lead", "other"), b.entity("other", "other")]
    return _r157_run(b, r, ve0, others, init, acts)


def _decel(p: Decel, b: _Build) -> PresetRun:
    r = _r157(b)
    s_lead0 = b.s_front0(p.ve0) + b.k.follow_thw * p.ve0 + b.z.other_length / 2
    start = b.dt - b.k.lead_in
    init = _place("other", RoadPosition(r.id, s_lead0 + p.ve0 * start, 0.0), p.ve0)
    brake = SpeedAction(
        TransitionDynamics(Shape.LINEAR, Dimension.RATE, p.decel), AbsoluteSpeed(0.0)
    )
    acts = [_act("decel", "other", b.at(0.0), Action("decel", brake))]
    return _r157_run(b, r, p.ve0, [b.entity("other", "other")], list(init), acts)


def _stationary(p: Stationary, b: _Build) -> PresetRun:
    r = _r157(b)
    s_c = b.s_front0(p.ve0) + p.gap + b.z.other_length / 2
    init = _place("other", RoadPosition(r.id, s_c, 0.0), 0.0)
    return _r157_run(b, r, p.ve0, [b.entity("other", "other")], list(init), [])


def _dart_out(p: DartOut, b: _Build) -> PresetRun:
    k, z = b.k, b.z
    network = b.road(
        "street.net.xml", build_intersection, IntersectionParams(lane_width=k.lane_width)
    )
    roads = b.lanes(network)
    edge = network.sumo.getEdge("w_in")
    sumo_lane = next(ln for ln in edge.getLanes() if ln.allows("passenger"))
    lane = sumo_lane_id(edge.getLaneNumber(), sumo_lane.getIndex())
    exit_edge = network.sumo.getEdge("e_out")
    exit_lane = next(ln for ln in exit_edge.getLanes() if ln.allows("passenger"))
    vp = p.ped_speed
    s_path = (
        roads.odr.road("w_in").length - 30.0
    )  # the child's path crosses 30 m before the junction
    d_start = -(k.lane_width / 2 + k.ped_start_beyond_lane)
    d_impact = -z.ego_width / 2 + p.impact_fraction * z.ego_width
    # without braking, the ego front reaches the path when the child reaches d_impact
    t_hit = (s_path - z.child_depth / 2 - b.s_front0(p.ve0)) / p.ve0
    t_go = t_hit - (d_impact - d_start) / vp
    # the child walks on across the road, past the end of the run
    t_end = t_go + b.duration + k.lead_in + 10.0
    across = Orientation(math.pi / 2)
    walk = Trajectory(
        "walk",
        Polyline(
            (
                Vertex(b.scenario_time(t_go), LanePosition("w_in", lane, s_path, d_start, across)),
                Vertex(
                    b.scenario_time(t_end),
                    LanePosition("w_in", lane, s_path, d_start + vp * (t_end - t_go), across),
                ),
            )
        ),
    )
    ego_s = k.ego_start_s - z.ego_length / 2
    route = AssignRouteAction(
        "straight on",
        (
            LanePosition(
                "e_out", sumo_lane_id(exit_edge.getLaneNumber(), exit_lane.getIndex()), 1.0
            ),
        ),
    )
    init = [
        *_place("ego", LanePosition("w_in", lane, ego_s), p.ve0),
        InitAction("ego", Action("ego route", route)),
        *_place("child", LanePosition("w_in", lane, s_path, d_start), 0.0),
    ]
    entities = [b.entity("ego", "ego"), b.entity("child", "child")]
    if p.parked_car:
        s_parked = s_path - k.parked_gap_to_path - z.other_length / 2
        d_parked = -(k.lane_width / 2 + k.kerb_offset)
        init += _place("parked", LanePosition("w_in", lane, s_parked, d_parked), 0.0)
        entities.insert(1, b.entity("parked", "other"))
    go = FollowTrajectoryAction(walk, Timing(absolute=True))
    acts = [_act("dart-out", "child", b.before(t_go), Action("dart-out", go))]
    x, y, _, _ = roads.odr.lane_pose("w_in", lane, np.array([s_path]), np.array([d_impact]))
    conflict = (float(x[0]), float(y[0]))
    sc = _scenario("dart-out", entities, init, acts)
    return PresetRun(sc, network, roads, b.scoring("child", conflict))


def _city(p: City, b: _Build) -> PresetRun:
    world = b.world
    if world is None:
        network = RoadNetwork(build_city_grid(b.workdir / "city.net.xml", CityGridParams()))
    else:
        network = world.network()
    sumo = world.sumo if world is not None else None
    routes: tuple[Path, ...] = ()
    if sumo is None:  # a SUMO scenario brings its own demand; other roads get generated demand
        routes = (
            write_demand(
                network.path,
                b.workdir / "demand.rou.xml",
                DemandConfig(
                    vehicles_per_hour=p.vehicles_per_hour,
                    persons_per_hour=p.persons_per_hour,
                    end=p.warmup + b.duration + 60.0,
                    seed=b.seed,
                    vehicle_mix={"car": 0.85, "truck": 0.05, "bus": 0.05, "motorcycle": 0.05},
                ),
            ),
        )
    elif sumo.end is not None and sumo.begin + p.warmup + b.duration > sumo.end:
        raise HiyariError(
            f"{sumo.config}: the run (warmup {p.warmup:g} s + {b.duration:g} s from begin "
            f"{sumo.begin:g} s) ends after the scenario's end {sumo.end:g} s"
        )
    edges = [network.sumo.getEdge(e) for e in _long_route(network)]

    def on(edge: object, s: float) -> LanePosition:
        lane = next(ln for ln in edge.getLanes() if ln.allows("passenger"))
        s = min(s, lane.getLength() / 2)  # an imported map has edges shorter than s
        return LanePosition(edge.getID(), sumo_lane_id(edge.getLaneNumber(), lane.getIndex()), s)

    route = AssignRouteAction("across the city", tuple(on(e, 1.0) for e in edges[1:]))
    init = [
        *_place("ego", on(edges[0], 5.0 - b.z.ego_length / 2), p.ve0),
        InitAction("ego", Action("ego route", route)),
    ]
    # SUMO keeps the ego to lights and right of way; its speed is the stack's
    mode = ControllerSpec("ego stack", {"hiyari:speed_mode": str(b.k.city_speed_mode)})
    ego = replace(b.entity("ego", "ego"), controller=mode)
    sc = _scenario("city", [ego], init, [])
    scoring = Scoring("", None, math.inf, 0.0)
    return PresetRun(sc, network, b.lanes(network), scoring, routes, p.warmup, sumo)


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
    roads: RoadCache | None = None,
    world: World | None = None,
) -> PresetRun:
    """The preset run of one concrete scenario; road files are written into ``workdir``, or
    taken from ``roads`` (built there once per process) when given. ``world``: the map or
    SUMO scenario a city run drives in (other types refuse one)."""
    params = typed_parameters(cs)
    if world is not None and not isinstance(params, City):
        raise HiyariError(
            f"a {cs.type} scenario runs on its own road: only city scenarios run on a map or "
            "a SUMO scenario"
        )
    workdir.mkdir(parents=True, exist_ok=True)
    k, z = k or ScenarioConstants(), sizes or ActorSizes()
    b = _Build(workdir, k, z, cs.seed, cs.duration, cs.step_length, roads, world)
    return BUILDERS[type(params)](params, b)


#: Edges tried at each end of the ego's route on a net without fringe edges.
_ROUTE_CANDIDATES = 20


def _long_route(network: RoadNetwork) -> list[str]:
    """A long car route across the network: between the most distant boundary edges (on a
    net whose edges all lead on, as imported maps with U-turns at dead ends: between the
    edges farthest from the network's centre)."""
    n = network.sumo
    cars = [e for e in n.getEdges() if e.allows("passenger") and not e.isSpecial()]
    starts = [e for e in cars if not e.getIncoming()] or _outermost(cars)
    ends = [e for e in cars if not e.getOutgoing()] or _outermost(cars)
    pairs = sorted(
        ((a, b) for a in starts for b in ends if a.getFromNode() is not b.getToNode()),
        key=lambda ab: -math.dist(ab[0].getFromNode().getCoord(), ab[1].getToNode().getCoord()),
    )
    for a, b in pairs:
        path, _ = n.getShortestPath(a, b, vClass="passenger")
        if path:
            return [e.getID() for e in path]
    raise HiyariError(f"{network.path}: no route across the network for the ego")


def _outermost(edges: list) -> list:
    """The ``_ROUTE_CANDIDATES`` edges whose middle lies farthest from the edges' centre."""
    mid = np.array([np.mean([p[:2] for p in e.getShape()], axis=0) for e in edges])
    far = np.argsort(-np.linalg.norm(mid - mid.mean(axis=0), axis=1), kind="stable")
    return [edges[i] for i in far[:_ROUTE_CANDIDATES]]
