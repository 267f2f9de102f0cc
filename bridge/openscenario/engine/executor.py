"""The storyboard executor: inserts a scenario's entities into SUMO, then, once per step,
evaluates every trigger on the WorldState, advances the storyboard and moves the scripted
actors exactly (kinematically, ``moveToXY`` with SUMO's own checks off).

The ego is driven by the ego stack (hiyari's or a user's) unless its controller says
``hiyari:driver = storyboard``; each StepReport says whether the storyboard drives it and
lists the storyboard actions addressed to a stack-driven ego (not applied). Everything not in
the scenario stays SUMO traffic.

Use (the closed loop owns stepping)::

    engine = ScenarioEngine(scenario, RoadLanes.from_files(xodr, net), dt)
    report = engine.start(sim)            # entities inserted, Init applied
    while not report.finished:
        world = sim.step()
        report = engine.step(sim, world)  # triggers on this state; actors placed for the next
        ... ego stack on ``world`` -> sim.set_speed(engine.ego, v)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from hiyari.bridge.openscenario.engine.actions import ActionStarter, Instance
from hiyari.bridge.openscenario.engine.conditions import ConditionBank
from hiyari.bridge.openscenario.engine.elements import (
    NO_TRANSITION,
    RUNNING,
    STANDBY,
    ElementTree,
    active_triggers,
    ends_bottom_up,
)
from hiyari.bridge.openscenario.engine.followers.ego_ramp import EgoRamp
from hiyari.bridge.openscenario.engine.frames.trajectory import check_trajectory_frames
from hiyari.bridge.openscenario.engine.global_actions import is_global
from hiyari.bridge.openscenario.engine.kernels.command_kernel import command_step
from hiyari.bridge.openscenario.engine.kernels.snapshot import (
    F_ACCEL,
    F_HEADING,
    F_ROAD_CODE,
    F_ROAD_DIR,
    F_ROAD_S,
    F_ROAD_T,
    F_SPEED,
    Snapshot,
    gather_entities,
)
from hiyari.bridge.openscenario.engine.kernels.step_kernel import quiet_step
from hiyari.bridge.openscenario.engine.kernels.tables import (
    CommandArrays,
    ElementArrays,
    EntityFields,
    GatherArrays,
    WorldArrays,
)
from hiyari.bridge.openscenario.engine.measured import entity_holds, time_of_day_holds
from hiyari.bridge.openscenario.engine.motion import (
    Actor,
    ActorTable,
    PathMotion,
    advance_road_actors,
    finish_pass,
    forward,
    quiet_motion,
    read_targets,
)
from hiyari.bridge.openscenario.engine.paths.sampled import SampledPath
from hiyari.bridge.openscenario.engine.positions import Pose, PoseResolver
from hiyari.bridge.openscenario.engine.preflight import check_decided_actions
from hiyari.bridge.openscenario.engine.signals import ControllerClock, phase_index, sumo_state
from hiyari.bridge.openscenario.engine.values import ValueStore
from hiyari.bridge.openscenario.model.actions import (
    AssignRouteAction,
    LightStateAction,
    VisibilityAction,
)
from hiyari.bridge.openscenario.model.conditions import (
    Condition,
    TimeOfDayCondition,
    TrafficSignalCondition,
    TrafficSignalControllerCondition,
)
from hiyari.bridge.openscenario.model.entities import EntityKind
from hiyari.bridge.openscenario.model.global_actions import Environment
from hiyari.bridge.openscenario.model.storyboard import Scenario, SignalController
from hiyari.errors import HiyariError
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.commands import VehicleType
from hiyari.traffic.simulation import Simulation
from hiyari.traffic.world_state import WorldState

_SHAPE = {
    ActorClass.CAR: "passenger",
    ActorClass.TRUCK: "truck",
    ActorClass.BUS: "bus",
    ActorClass.MOTORCYCLE: "motorcycle",
    ActorClass.BICYCLE: "bicycle",
    ActorClass.PEDESTRIAN: "pedestrian",
}
#: SUMO's signal bits of OpenSCENARIO's vehicle lights (flashing indicators blink in SUMO too).
SUMO_SIGNALS = {
    "indicatorRight": 1,
    "indicatorLeft": 2,
    "warningLights": 4,
    "brakeLights": 8,
    "lowBeam": 16,
    "daytimeRunningLights": 16,
    "fogLights": 32,
    "fogLightsFront": 32,
    "fogLightsRear": 32,
    "highBeam": 64,
    "reversingLights": 128,
    "specialPurposeLights": 1024,
}
#: Top speed given to SUMO types when the scenario names none, m/s.
DEFAULT_MAX_SPEED = 100.0


@dataclass(frozen=True)
class _View:
    """What the storyboard's element states decide, kept until one changes (``version``: the
    length of the element log): the triggers evaluated now (T,), the entities the storyboard
    drives (E,), those whose road coordinates active conditions read (E,), of these the
    ones located on the map (not driven; their indices) and the driven ones (E,), and whether
    the storyboard drives the ego."""

    version: int
    active: np.ndarray
    driven: np.ndarray
    need: np.ndarray
    located: list[int]
    own: np.ndarray
    ego_driven: bool


class StepReport(NamedTuple):
    """What one update did. ``time``: scenario time of the evaluated state (s). (A named
    tuple: immutable, and built every step at a quarter of a frozen dataclass's cost.)"""

    time: float
    finished: bool
    ego_storyboard_driven: bool
    started: tuple[str, ...] = ()
    ended: tuple[str, ...] = ()
    ego_requests: tuple[str, ...] = ()


class ScenarioEngine:
    """Executes one scenario on one running Simulation (see the module docstring)."""

    def __init__(self, scenario: Scenario, roads: RoadLanes, step_length: float) -> None:
        self.scenario = scenario
        self.roads = roads
        self.dt = step_length
        self.ego = scenario.ego
        self.names = [e.name for e in scenario.entities]
        self.index = {n: i for i, n in enumerate(self.names)}
        self.table = ActorTable(len(self.names))
        self.actors = {
            e.name: Actor(e.name, e, self.table, k) for k, e in enumerate(scenario.entities)
        }
        self._actor_list = list(self.actors.values())
        self._ego_row = self.index[self.ego] if self.ego is not None else -1
        self.tree = ElementTree(scenario.storyboard)
        self.resolver = PoseResolver(roads.odr, self.pose_of)
        self.starter = ActionStarter(self)
        #: Variables and parameters as they are now (actions may change them).
        self.values = ValueStore(
            scenario.variables, scenario.parameters, scenario.parameter_types, scenario.monitors
        )
        #: The environment the latest EnvironmentAction set (None: none yet).
        self.environment: Environment | None = None
        self.bank = ConditionBank(
            self.tree.triggers,
            self.index,
            self.tree.index,
            self.values,
            self.resolver.resolve,
            step_length,
        )
        self.bank.python_eval = self._measure_in_python
        check_trajectory_frames(scenario.storyboard, self.tree.triggers)
        #: The trajectory each entity was given by its latest FollowTrajectoryAction (the
        #: frame of conditions in trajectory coordinates).
        self.trajectory_of: dict[str, SampledPath] = {}
        self.instances: dict[int, list[Instance]] = {}
        self.owner: dict[tuple[str, str], int] = {}
        self.controller = {e.name: e.controller for e in scenario.entities}
        self.active_domains = {
            e.name: {"lateral": True, "longitudinal": True} for e in scenario.entities
        }
        #: Continuous distance actions by (actor, domain): each step, after the motion, they
        #: put their actor at its gap again.
        self.keepers: dict[tuple[str, str], Callable[[], None]] = {}
        #: Traffic actions running by name (sources, sinks, swarms) and SUMO vehicles they
        #: inserted so far.
        self.traffic: dict[str, object] = {}
        self.traffic_count = 0
        #: The signal controllers the scenario defines, running (from the start).
        self.controllers: dict[str, ControllerClock] = {}
        #: VisibilityActions in force by entity; light modes by (entity, light).
        self.visibility: dict[str, VisibilityAction] = {}
        self.lights: dict[tuple[str, str], str] = {}
        #: The path the storyboard gives a stack-driven ego to steer along (its speed stays
        #: the stack's), None when it steers on its SUMO route.
        self.ego_path: PathMotion | None = None
        #: A stack-driven ego's Init SpeedAction with a transition: its ramp to the target,
        #: which is the stack's set speed (None: the Init speed is reached at once).
        self.ego_ramp: EgoRamp | None = None
        self.t0 = 0.0
        self.now = 0.0
        self.finished = False
        self._world: WorldState | None = None
        self._rows: dict[str, int] = {}
        self._ids: list[str] | None = None
        self._entity_rows = np.full(len(self.names), -1, dtype=np.intp)
        self._located: dict[str, Pose] = {}
        self._started: list[str] = []
        self._ended: list[str] = []
        self._ego_requests: list[str] = []
        self._length = np.array([e.length for e in scenario.entities])
        self._width = np.array([e.width for e in scenario.entities])
        acts, events = self.tree.of_kind("act"), self.tree.of_kind("event")
        self._act_ix = np.array([a.index for a in acts], dtype=np.intp)
        self._act_start = np.array([a.start_trigger for a in acts], dtype=np.intp)
        self._act_stop = np.array([a.stop_trigger for a in acts], dtype=np.intp)
        real = [e for e in events if e.model is not None]
        self._ev_ix = np.array([e.index for e in real], dtype=np.intp)
        self._ev_parent = np.array([e.parent for e in real], dtype=np.intp)
        self._ev_trig = np.array([e.start_trigger for e in real], dtype=np.intp)
        self._has_children = np.array([bool(e.children) for e in self.tree.elements])
        # every element with children, bottom-up: events first, stories last
        self._end_order = np.array(
            [
                e.index
                for k in ("event", "maneuver", "maneuverGroup", "act", "story")
                for e in self.tree.of_kind(k)
            ],
            dtype=np.int64,
        )
        self._cx = np.array([e.centre[0] for e in scenario.entities])
        self._cy = np.array([e.centre[1] for e in scenario.entities])
        self._centre_offset = np.stack([self._cx, self._cy], 1).reshape(-1, 2)
        # SUMO lane of each row, kept until its road, lane or lane section changes
        n = len(self.names)
        self._lane_key = np.full((n, 3), -2, dtype=np.int64)  # road code, lane, section
        self._edge: list[str] = [""] * n
        self._lane_index: list[int] = [-1] * n
        self._sent_speed = np.full(n, np.nan)  # speed last sent to SUMO per entity, m/s
        # the rows commanded (inserted and driven), their names and their command table
        # (see _command_table), for the view version and insert count they were found at
        no_rows = np.zeros(0, np.intp)
        self._moved: tuple[np.ndarray, list[str], CommandArrays, np.ndarray] = (
            no_rows, [], *self._command_table(no_rows),
        )  # fmt: skip
        self._moved_key: tuple[int, int] = (-1, -1)
        self._inserts = 0
        self._types: set[str] = set()  # entities whose SUMO vehicle type is defined
        self._lanes_of: tuple[np.ndarray | None, list[str], list[int]] = (None, [], [])
        # table rows on roads / following paths, for the view and motion versions
        self._advance_rows: tuple[tuple[int, int], np.ndarray, list[int]] | None = None
        # the snapshot's arrays, filled in place every step (see snapshot.gather_entities)
        self._present = np.zeros(n, dtype=bool)
        self._centre, self._ref = np.zeros((n, 2)), np.zeros((n, 2))
        self._ent = np.zeros((7, n))
        self._no_contact = np.zeros(n, dtype=bool)  # never written
        out = self._ent
        self._snap = Snapshot(
            0.0, self._present, self._ref, self._centre, out[F_HEADING], self._length,
            self._width, out[F_SPEED], out[F_ACCEL], self._no_contact, out[F_ROAD_S],
            out[F_ROAD_T], out[F_ROAD_DIR], set(), self._no_contact, out[F_ROAD_CODE],
        )  # fmt: skip
        # the same arrays as the kernels take them, for steps without contacts and without
        # end-of-road conditions (the quiet step, and the gather before entities are located)
        self._fields = EntityFields(
            self._present, self._centre, self._ref, out[F_HEADING], self._length, self._width,
            out[F_SPEED], out[F_ACCEL], self._no_contact, out[F_ROAD_S], out[F_ROAD_T],
            out[F_ROAD_DIR], self.bank.no_contact, self._no_contact, out[F_ROAD_CODE],
        )  # fmt: skip
        self._near: dict[str, tuple[str, float]] = {}  # last road and s of located entities
        self._view_cache: _View | None = None
        # log length / (log length, motion version) at the start of the latest storyboard
        # update / action-ending pass that changed nothing (-1 / None: it changed something)
        self._idle: tuple[int, tuple[int, int] | None] = (-1, None)
        self._cleared = -1  # log length when the element transitions were last cleared
        self._quiet: tuple[tuple, np.ndarray | None, tuple | None] = ((), None, None)

    # ------------------------------------------------------------------ who drives what
    def storyboard_drives(self, name: str) -> bool:
        """Whether the storyboard moves entity ``name`` (every entity but a stack-driven ego)."""
        if name != self.ego:
            return True
        ctrl = self.controller.get(name)
        return (
            ctrl is not None
            and ctrl.drives == "storyboard"
            and any(self.active_domains[name].values())
        )

    def road_pose(self, name: str) -> Pose:
        """``pose_of`` with road coordinates located anew for a scripted actor off the roads'
        frames (following a path: its road, lane and s are not kept)."""
        a = self.actors[name]
        if a.free and self.storyboard_drives(name):
            return self.resolver.at_xy(a.x, a.y, a.h)
        return self.pose_of(name)

    def travel_direction(self, name: str) -> float:
        """+1 when entity ``name`` travels towards increasing road s, else -1 (its lane's
        direction; a scripted actor's own, which a wrong-way heading turns)."""
        a = self.actors[name]
        if self.storyboard_drives(name) and a.road and not a.free:
            self.table.refresh(self.roads.odr)
            return float(self.table.direction[a.k])
        p = self.pose_of(name)
        return forward(self.roads.odr, p.road, p.lane) if p.road else 1.0

    def _start_controllers(self) -> None:
        """Clocks of the scenario's signal controllers: each starts ``delay`` s after its
        reference's start (chains of references add up)."""
        by_name = {c.name: c for c in self.scenario.signal_controllers}

        def start(c: SignalController, seen: tuple[str, ...]) -> float:
            if not c.reference:
                return c.delay
            if c.reference in seen or c.reference not in by_name:
                raise HiyariError(
                    f"{self.scenario.source}: signal controller {c.name!r} refers to "
                    f"{c.reference!r}, which is not a controller here (or refers back)"
                )
            return c.delay + start(by_name[c.reference], (*seen, c.name))

        self.controllers = {c.name: ControllerClock(c, start(c, ())) for c in by_name.values()}

    def _measure_in_python(self, c: Condition) -> bool:
        """Whether condition ``c`` (relative clearance, traffic signal) holds now."""
        b = c.body
        if isinstance(b, TrafficSignalCondition):
            want = sumo_state(self._sim, b.signal, b.state, c.source)
            return self._sim.signal_states([b.signal])[b.signal] == want
        if isinstance(b, TrafficSignalControllerCondition) and b.controller in self.controllers:
            return self.controllers[b.controller].in_phase(b.phase)
        if isinstance(b, TrafficSignalControllerCondition):
            want = phase_index(self._sim, b.controller, b.phase, c.source)
            return self._sim.signal_phase(b.controller) == want
        if isinstance(b, TimeOfDayCondition):
            return time_of_day_holds(self, b, c.source)
        return entity_holds(self, b)

    def hidden_from_sensors(self) -> list[str]:
        """Entities a VisibilityAction hides from the ego's sensors now."""
        return [n for n, v in self.visibility.items() if not v.sensors]

    def set_light(self, name: str, b: LightStateAction) -> None:
        """Set a light's mode; a vehicle's lamps go to SUMO's signals (user-defined lights
        are kept here only)."""
        self.lights[(name, b.light)] = b.mode
        a = self.actors[name]
        if b.user_defined or not a.inserted:
            return
        bits = 0
        for (who, light), mode in self.lights.items():
            if who == name and mode != "off":
                bits |= SUMO_SIGNALS.get(light, 0)
        self._sim.set_signals(name, bits)

    def remove_entity(self, name: str, where: str) -> None:
        """Take entity ``name`` out of SUMO now (DeleteEntityAction); its running actions stop."""
        a = self._known(name, where)
        if not a.inserted:
            return
        for insts in list(self.instances.values()):
            for inst in insts:
                if inst.actor == name:
                    self.starter.cancel(inst)
        self._sim.remove_actor(name)
        a.inserted = False
        self._inserts += 1

    def add_entity(self, name: str, pose: Pose, where: str) -> None:
        """Put entity ``name`` into SUMO at ``pose`` (AddEntityAction); nothing when it is in."""
        a = self._known(name, where)
        if a.inserted:
            return
        self.starter.place(a, pose)
        self._insert(self._sim, name)

    def _known(self, name: str, where: str) -> Actor:
        a = self.actors.get(name)
        if a is None:
            raise HiyariError(f"{where}: no entity {name!r} in the scenario")
        return a

    def drive_ego(self, sim: Simulation, speed: float, move: bool = True) -> None:
        """Command the stack-driven ego's ``speed`` (m/s, >= 0) for the next step: SUMO drives
        it on its route, or, when the storyboard gave it a path, it is moved that far along
        the path (backwards when its Init speed was negative: SUMO then carries its box
        turned round, so the stack sees the scene it backs into ahead of it). ``move``: False
        places it where it is on its path (at the start). While the Init ramp runs
        (``ego_ramp``) the ramp's speed is commanded unless ``speed`` brakes."""
        if self.ego_ramp is not None and move:
            speed = self.ego_ramp.command(speed, self.speed_of(self.ego), self.dt)
        m = self.ego_path
        if m is None:
            sim.set_speed(self.ego, speed)
            return
        x, y, h, _, done = m.advance(self.now, speed * self.dt if move else 0.0)
        if done:
            d = m.path.direction(m.path.length)
            ahead = np.array([[x, y], [x + 1e4 * math.cos(d), y + 1e4 * math.sin(d)]])
            self.ego_path = PathMotion(SampledPath.through(ahead), None, False, 0.0, m.reverse)
        e = self.actors[self.ego].entity
        c, s = math.cos(h), math.sin(h)
        cx = x + e.centre[0] * c - e.centre[1] * s
        cy = y + e.centre[0] * s + e.centre[1] * c
        h_sumo = h + math.pi if m.reverse else h
        sim.move_vehicle(self.ego, cx, cy, h_sumo, e.length, speed=speed)

    def ego_set_speed(self) -> float:
        """The speed a stack-driven ego's stack keeps (m/s, >= 0): the target of its Init
        SpeedAction (as resolved at Init), else its speed after the Init actions."""
        if self.ego_ramp is not None:
            return self.ego_ramp.goal
        return abs(self.actors[self.ego].v)  # a backing ego's speed is negative

    def _driven(self) -> np.ndarray:
        """(E,) whether the storyboard moves each entity (all but a stack-driven ego)."""
        return self._view().driven

    def pose_of(self, name: str) -> Pose:
        """Current reference-point pose of entity ``name`` with road coordinates."""
        a = self.actors.get(name)
        if a is None:
            raise HiyariError(f"no entity {name!r} in the scenario")
        if self._world is None or self.storyboard_drives(name):
            return Pose(a.x, a.y, a.z, a.h, a.road, a.lane, a.s, a.t)
        if name not in self._located:
            self._located[name] = self._locate(name)
        return self._located[name]

    def speed_of(self, name: str) -> float:
        """Current speed of entity ``name`` (m/s)."""
        if self._world is None or self.storyboard_drives(name):
            return self.actors[name].v
        row = self._rows.get(name, -1)
        return float(self._world.speed[row]) if row >= 0 else self.actors[name].v

    def _locate(self, name: str) -> Pose:
        w, row = self._world, self._rows.get(name, -1)
        if row < 0:
            a = self.actors[name]
            return Pose(a.x, a.y, a.z, a.h, a.road, a.lane, a.s, a.t)
        e = self.actors[name].entity
        h = float(w.heading[row])
        if name == self.ego and self.ego_path is not None and self.ego_path.reverse:
            h = math.remainder(h + math.pi, 2 * math.pi)  # SUMO carries a backing ego turned
        x = float(w.xyz[row, 0]) - e.centre[0] * math.cos(h) + e.centre[1] * math.sin(h)
        y = float(w.xyz[row, 1]) - e.centre[0] * math.sin(h) - e.centre[1] * math.cos(h)
        origin = self.roads.origin_of(str(w.lane[row]))
        road = origin[0] if origin else None
        near = self._near.get(name)
        if road is not None and near is not None and near[0] == road:
            rc = self.roads.odr.locate_near(road, x, y, near[1])  # s moved by about v dt
        else:
            rc = self.roads.odr.locate(np.array([x]), np.array([y]), road)[0]
        self._near[name] = (rc.road, rc.s)
        return Pose(x, y, float(w.xyz[row, 2]), h, rc.road, rc.lane, rc.s, rc.t)

    # ------------------------------------------------------------------ start
    def start(self, sim: Simulation) -> StepReport:
        """Apply the Init actions, check the story actions whose outcome they decide
        (engine.preflight) and insert every entity into SUMO. The state after SUMO's next
        step is scenario time 0 (the Init state)."""
        self.t0 = sim.time + self.dt
        self._sim = sim
        self._start_controllers()
        group = self.tree.elements[self.tree.init].children[0]
        maneuver = self.tree.elements[group].children[0]
        for i in (self.tree.init, group, maneuver, self.tree.init_event):
            self.tree.start(i, 0.0)
        for ai in self.tree.elements[self.tree.init_event].children:
            ia = self.tree.elements[ai].model
            self._start_action(ai, ia.action, ia.entity, 0.0, init=True)
        self.bank.refresh_values()
        for name, a in self.actors.items():
            if not a.road and not a.free:
                raise HiyariError(f"{self.scenario.source}: entity {name!r} has no Init position")
        # an action the Init state already dooms fails now, before anything runs
        check_decided_actions(self)
        self.bank.resolve_fixed()
        for name in self.names:
            self._insert(sim, name)
        if self.ego_path is not None and not self.storyboard_drives(self.ego):
            self.drive_ego(sim, abs(self.actors[self.ego].v), move=False)
        self._finish_actions(0.0)
        self._command(sim)
        return self._report()

    def _insert(self, sim: Simulation, name: str) -> None:
        a = self.actors[name]
        e = a.entity
        scripted = self.storyboard_drives(name)
        cls = e.actor_class
        vclass = (
            "ignoring"
            if scripted
            else ("passenger" if cls == ActorClass.PEDESTRIAN else _SHAPE[cls])
        )
        if name not in self._types:  # once: an entity added again keeps its type
            self._types.add(name)
            vt = VehicleType(
                f"hiyari_{name}",
                e.length,
                e.width,
                e.height,
                max_speed=max(e.max_speed or 0.0, DEFAULT_MAX_SPEED),
                vclass=vclass,
                shape=_SHAPE[cls],
            )
            sim.define_vehicle_type(vt)
        edge, lane_index, pos = self._insertion_point(a)
        route = self._sumo_route(name, edge) if not scripted else [edge]
        sim.add_vehicle(name, route, f"hiyari_{name}", lane_index, pos, abs(a.v), scripted=True)
        mode = e.controller.properties.get("hiyari:speed_mode") if e.controller else None
        if mode is not None and not scripted:  # SUMO's own checks under the stack's speed
            if not mode.isdigit():
                raise HiyariError(
                    f"{self.scenario.source}: {name}: hiyari:speed_mode {mode!r} is not a "
                    "SUMO speed mode (a non-negative integer)"
                )
            sim.set_speed_mode(name, int(mode))
        a.inserted = True
        self._inserts += 1

    def _sumo_route(self, name: str, edge: str) -> list[str]:
        """SUMO route of a stack-driven entity from ``edge``: on through the edges of its Init
        AssignRouteAction's waypoints (the route it is told to follow; consecutive ones must
        be connected), else the road ahead."""
        for ia in self.scenario.storyboard.init:
            if ia.entity == name and isinstance(ia.action.body, AssignRouteAction):
                route = [edge]
                for w in ia.action.body.waypoints:
                    p = self.resolver.resolve(w)
                    ln = self.roads.sumo_lane(p.road, p.lane, p.s) if p.road else None
                    if ln is not None and ln.edge != route[-1]:
                        if not self.roads.connects(route[-1], ln.edge):
                            raise HiyariError(
                                f"{self.scenario.source}: {name} cannot drive its route "
                                f"{ia.action.body.name!r} in SUMO: no connection from edge "
                                f"{route[-1]!r} to edge {ln.edge!r}"
                            )
                        route.append(ln.edge)
                return route
        return self.roads.route_from(edge)

    def _insertion_point(self, a: Actor) -> tuple[str, int, float]:
        """SUMO edge, lane index and front position for inserting ``a``."""
        front = a.entity.centre[0] + 0.5 * a.entity.length
        if a.road and not a.free:
            direction = forward(self.roads.odr, a.road, a.lane)
            s_front = float(
                np.clip(a.s + direction * front, 0.0, self.roads.odr.road(a.road).length)
            )
            lane = self.roads.sumo_lane(a.road, a.lane, s_front)
            if lane is not None:
                p = self.roads.place(a.road, a.lane, s_front, a.t - self._centre_t(a))
                return lane.edge, lane.index, float(np.clip(p.pos, 0.0, lane.length))
        # off the imported lanes: insert on the nearest lane, moveToXY places it exactly
        lanes = self.roads.lanes()
        best = min(lanes, key=lambda ln: float(np.min(np.hypot(*(ln.shape - [a.x, a.y]).T))))
        return best.edge, best.index, 0.5 * best.length

    def _centre_t(self, a: Actor) -> float:
        return float(self.roads.odr.road(a.road).lane_centre_t(a.lane, np.array([a.s]))[0][0])

    # ------------------------------------------------------------------ step
    def step(self, sim: Simulation, world: WorldState) -> StepReport:
        """One update on ``world`` (the state after SUMO's latest step): evaluate triggers,
        advance the storyboard, and place the scripted actors for the next step."""
        self.now = world.time - self.t0
        self._world = world
        self._map_rows(world)
        self._located = {}
        self._started, self._ended, self._ego_requests = [], [], []
        if self.finished:
            return self._report()
        for t in list(self.traffic.values()):
            t.update(self, sim, world)
        for clock in self.controllers.values():
            clock.update(sim, self.now, str(self.scenario.source))
        quiet = self._quiet_args()
        if quiet is not None:
            if self.table.long_targets:
                read_targets(self.table)
            bank = self.bank
            n_fired, ended, missing, lat_ended, placed, changed = quiet_step(
                _world_arrays(world), self.now, bank.step_no, self.now + self.dt, *quiet
            )
            bank.step_no += 1
            bank.n_fired = n_fired
            if not n_fired:
                if ended or not placed:  # the storyboard ends them, then the commands
                    rows = self._motion_rows()[0]
                    finish_pass(
                        self.roads.odr, self._actor_list, rows, self.table.road[rows[0]],
                        ended, missing, lat_ended, placed,
                    )  # fmt: skip
                    changed = None
                return self._command_and_send(sim, changed)
            fired = bank.fired
        else:
            view = self._view()
            snap, gather = self._snapshot(world, sim, view)
            fired = self.bank.evaluate(
                snap, view.active, self.tree.state, self.tree.transition, gather
            )
        if len(self.tree.log) != self._cleared:  # transitions are set with a log entry only
            self.tree.transition[:] = NO_TRANSITION
            self._cleared = len(self.tree.log)
        any_fired = self.bank.n_fired > 0
        if any_fired and fired[0]:
            self.finished = True
            for story in self.tree.of_kind("story"):
                self.tree.stop(story.index, self.now)
            return self._report()
        # with nothing fired and no element changed since an update that changed nothing,
        # the update would change nothing again
        if any_fired or len(self.tree.log) != self._idle[0]:
            version = len(self.tree.log)
            self._acts(fired)
            self._events(fired)
            self._idle = (version if len(self.tree.log) == version else -1, self._idle[1])
        # when no action can end (see _finish_actions), the commands are computed in the
        # motion pass's compiled call
        idle = (len(self.tree.log), self.table.motion_version) == self._idle[1] and not self.keepers
        return self._command_and_send(sim, self._advance(self._commands() if idle else None))

    def _command_and_send(self, sim: Simulation, changed: np.ndarray | None) -> StepReport:
        """Send the step's commands and return its report; ``changed``: the rows whose SUMO
        lane is to be looked up again, from a motion pass that computed the commands (None:
        it did not, as actions may have ended: they are ended first, then commanded)."""
        if changed is None:
            self._finish_actions(self.now)
            changed = command_step(*self._command_args())
        return self._send(sim, changed, self._report())

    def _quiet_args(self) -> tuple | None:
        """The arguments of ``step_kernel.quiet_step`` after the WorldState's table, the times
        and the evaluation number, when this step can be quiet; else None. A step is quiet
        when the latest storyboard update and action-ending pass changed nothing (see
        ``_idle``), the element transitions are cleared, the conditions read nothing the
        kernel does not gather (entities located on the map, positions, contacts, on-network
        states) and the motion runs in one compiled pass (``motion.quiet_motion``). Kept (or
        refused) until the element log, the motion or road versions, the inserts, the idle
        state or the entity rows change."""
        tb = self.table
        key = (
            len(self.tree.log), tb.motion_version, tb.road_version, self._inserts, self._idle,
            self._cleared,
        )  # fmt: skip
        cached = self._quiet
        if cached[0] == key and cached[1] is self._entity_rows and not tb.any_stale:
            return cached[2]
        self._quiet = (key, self._entity_rows, self._build_quiet(key[0]))
        return self._quiet[2]

    def _build_quiet(self, version: int) -> tuple | None:
        """See ``_quiet_args``; ``version``: the element log's length."""
        tb, bank = self.table, self.bank
        if not (
            version == self._idle[0] == self._cleared
            and self._idle[1] == (version, tb.motion_version)
            and not bank.needs_contacts and not bank.needs_on_net and not len(bank.point_rows)
            and not self.keepers and not bank.python_conditions and not self.traffic
            and not self.controllers
        ):  # fmt: skip
            return None
        view = self._view()
        if view.located:
            return None
        on_road, on_path = self._motion_rows()
        motion = None if on_path else quiet_motion(self.roads.odr, tb, on_road, self.dt)
        if motion is None:
            return None
        if bank.needs_road:
            bank.link_roads(tb.road_ids, self.resolver.graph)
        where = GatherArrays(self._entity_rows, self._centre_offset, view.own, view.driven)
        elements = ElementArrays(view.active, self.tree.state, self.tree.transition)
        return (
            tuple(where), tuple(bank.arrays), tuple(self._fields), tuple(elements), *motion,
            tuple(self._commands()),
        )  # fmt: skip

    def _report(self) -> StepReport:
        return StepReport(
            self.now,
            self.finished,
            self._view().ego_driven,
            tuple(self._started),
            tuple(self._ended),
            tuple(self._ego_requests),
        )

    def _view(self) -> _View:
        """The storyboard's current view (see _View), rebuilt when an element changed state
        (every change is logged, controller changes with their action's start)."""
        version = len(self.tree.log)
        if self._view_cache is None or self._view_cache.version != version:
            active = active_triggers(
                self.tree.state, self._act_ix, self._act_start, self._act_stop, self._ev_ix,
                self._ev_parent, self._ev_trig, len(self.tree.triggers),
            )  # fmt: skip
            driven = np.ones(len(self.names), dtype=bool)
            if self._ego_row >= 0:
                driven[self._ego_row] = self.storyboard_drives(self.ego)
            need = np.zeros(len(self.names), dtype=bool)
            if self.bank.needs_road:
                need = self.bank.road_entities(active)
            located = np.flatnonzero(need & ~driven).tolist()
            ego_driven = self.ego is not None and bool(driven[self._ego_row])
            self._view_cache = _View(
                version, active, driven, need, located, need & driven, ego_driven
            )
        return self._view_cache

    def _acts(self, fired: np.ndarray) -> None:
        tree, st = self.tree, self.tree.state
        for act in tree.of_kind("act"):
            i = act.index
            if st[i] == STANDBY and (act.start_trigger < 0 or fired[act.start_trigger]):
                if st[act.parent] == STANDBY:
                    tree.start(act.parent, self.now)
                tree.start(i, self.now)
                for g in act.children:
                    tree.start(g, self.now)
                    for m in tree.elements[g].children:
                        tree.start(m, self.now)
            elif st[i] == RUNNING and act.stop_trigger >= 0 and fired[act.stop_trigger]:
                self._stop(i)

    def _events(self, fired: np.ndarray) -> None:
        tree, st = self.tree, self.tree.state
        if not len(self._ev_ix):
            return
        go = np.append(fired, True)[self._ev_trig]  # trigger -1: none, starts at once
        due = (st[self._ev_ix] == STANDBY) & (st[self._ev_parent] == RUNNING) & go
        for i in self._ev_ix[due].tolist():
            ev = tree.elements[i]
            if st[i] != STANDBY:
                continue
            running = [c for c in tree.elements[ev.parent].children if c != i and st[c] == RUNNING]
            if running and ev.model.priority == "skip":
                tree.skip(i, self.now)
                continue
            if ev.model.priority == "override":
                for r in running:
                    self._stop(r)
            tree.start(i, self.now)
            group = tree.elements[tree.elements[ev.parent].parent].model
            for ai in ev.children:
                action = tree.elements[ai].model
                for actor in ("",) if is_global(action.body) else group.actors:
                    self._start_action(ai, action, actor, self.now)
        self.bank.refresh_values()

    def _stop(self, i: int) -> None:
        """Stop element ``i`` with its subtree, releasing the actors' domains."""
        for e in self._subtree(i):
            for inst in self.instances.pop(e, []):
                self.starter.cancel(inst)
                self._ended.append(self.tree.elements[e].name)
        self.tree.stop(i, self.now)

    def _subtree(self, i: int) -> list[int]:
        out, todo = [], [i]
        while todo:
            k = todo.pop()
            out.append(k)
            todo.extend(self.tree.elements[k].children)
        return out

    def _start_action(
        self, ai: int, action: object, actor: str, now: float, init: bool = False
    ) -> None:
        tree = self.tree
        if tree.state[ai] != RUNNING:
            tree.start(ai, now)
            self._started.append(action.name)
        inst = self.starter.start(ai, action, actor, now, init)
        self.instances.setdefault(ai, []).append(inst)

    # ------------------------------------------------------------------ motion
    def _motion_rows(self) -> tuple[np.ndarray, list[int]]:
        """The driven rows on roads and those following paths (kept for the view and motion
        versions: free changes only with the motion version)."""
        view, tb = self._view(), self.table
        key = (view.version, tb.motion_version)
        if self._advance_rows is None or self._advance_rows[0] != key:
            on_road = np.flatnonzero(view.driven & ~tb.free)
            self._advance_rows = (key, on_road, np.flatnonzero(view.driven & tb.free).tolist())
        return self._advance_rows[1], self._advance_rows[2]

    def _advance(self, command: CommandArrays | None = None) -> np.ndarray | None:
        """Move the driven actors to the next step; ``command``: the commands' table, whose
        ``command_step`` runs in the same compiled call when the pass ends nothing (returns
        its result; None: not run)."""
        nxt = self.now + self.dt
        on_road, on_path = self._motion_rows()
        changed = advance_road_actors(
            self.roads.odr, self._actor_list, on_road, nxt, self.dt, None if on_path else command
        )
        if on_path:
            self.starter.follow_paths(on_path, nxt)
        for keep in list(self.keepers.values()):
            keep()
        return changed

    def _finish_actions(self, now: float) -> None:
        """End the actions whose transitions or paths are over, then every element whose
        children are all complete (bottom-up). Skipped when neither the elements nor the
        actors' transitions changed since a pass that ended nothing."""
        version = (len(self.tree.log), self.table.motion_version)
        if version == self._idle[1]:
            return
        self._end_finished(now)
        after = (len(self.tree.log), self.table.motion_version)
        self._idle = (self._idle[0], version if after == version else None)

    def _end_finished(self, now: float) -> None:
        tree, st = self.tree, self.tree.state
        for ai, insts in list(self.instances.items()):
            if st[ai] == RUNNING and all(self.starter.done(x) for x in insts):
                tree.end(ai, now)
                self._ended.append(tree.elements[ai].name)
                del self.instances[ai]
        ends = ends_bottom_up(
            self._end_order, st, tree.parent, self._has_children, tree.executions,
            tree.max_runs,
        )  # fmt: skip
        for i in ends.tolist():
            tree.end(i, now)

    def _command(self, sim: Simulation) -> None:
        """Place every inserted scripted actor for the next step; its speed is sent only when
        it changed (SUMO holds the speed set last)."""
        self._send(sim, command_step(*self._command_args()), None)

    def _command_args(self) -> tuple:
        """The arguments of ``command_step``: the commands' table (:meth:`_commands`), the
        ActorTable's and its lane profile's (as plain tuples: see kernels.tables)."""
        tb = self.table
        return tuple(self._commands()), tuple(tb.arrays), tuple(tb.lanes(self.roads.odr))

    def _commands(self) -> CommandArrays:
        """The command table of the inserted scripted actors, kept while the rows hold (its
        arrays are updated in place)."""
        key = (self._view().version, self._inserts)
        if key != self._moved_key:
            rows = np.flatnonzero(self.table.inserted & self._driven())
            if not np.array_equal(rows, self._moved[0]):
                names = [self.names[k] for k in rows.tolist()]
                self._moved = (rows, names, *self._command_table(rows))
                left = np.ones(len(self.names), dtype=bool)
                left[rows] = False
                self._sent_speed[left] = np.nan  # others may set its speed meanwhile
            self._moved_key = key
        return self._moved[2]

    def _command_table(self, rows: np.ndarray) -> tuple[CommandArrays, np.ndarray]:
        """The command table of ``rows`` and the (4, m) array whose rows hold the SUMO commands
        and the speeds to send (front x, front y, SUMO angle, speed), read as lists in one
        call."""
        m = len(rows)
        cmd = np.empty((4, m))
        table = CommandArrays(
            rows, self._cx, self._cy, self._length, self._sent_speed, self._lane_key,
            np.empty((m, 2)), np.empty(m), cmd[3], cmd[:3],
        )  # fmt: skip
        return table, cmd

    def _send(
        self, sim: Simulation, changed: np.ndarray, report: StepReport | None
    ) -> StepReport | None:
        """Send the commands computed into the arrays of ``_moved`` and return ``report``
        (built before: Python after libsumo's calls runs in caches SUMO has just evicted);
        ``changed``: the rows whose SUMO lane is to be looked up again."""
        rows, names, _, cmd = self._moved
        edges, lanes = self._sumo_lanes(rows, changed)
        if names:
            front_x, front_y, angle, speed = cmd.tolist()
            sim.move_vehicle_fronts(names, edges, lanes, front_x, front_y, angle, speed)
        return report

    def _sumo_lanes(self, rows: np.ndarray, changed: np.ndarray) -> tuple[list[str], list[int]]:
        """SUMO edge ('' = any) and lane index (-1) of each of ``rows`` (for moveToXY), looked
        up again only for the ``changed`` rows (road, lane or lane section changed)."""
        tb = self.table
        if not len(changed) and rows is self._lanes_of[0]:
            return self._lanes_of[1], self._lanes_of[2]
        for k in changed.tolist():
            ln = None
            if self._lane_key[k, 2] >= 0:
                ln = self.roads.sumo_lane(tb.road[k], int(tb.lane[k]), float(tb.s[k]))
            self._edge[k], self._lane_index[k] = (ln.edge, ln.index) if ln else ("", -1)
        rl = rows.tolist()
        self._lanes_of = (rows, [self._edge[k] for k in rl], [self._lane_index[k] for k in rl])
        return self._lanes_of[1], self._lanes_of[2]

    # ------------------------------------------------------------------ snapshot
    def _located_road_coords(self, present: np.ndarray) -> None:
        """Road s of the box centre, t and direction (+1 / -1) of the present entities the
        storyboard does not drive whose road coordinates the active conditions read, located
        on the map (the driven ones come from the actor table in the snapshot kernel)."""
        out = self._ent
        for k in self._view().located:
            if not present[k]:
                continue
            p = self.pose_of(self.names[k])
            if p.road:
                out[F_ROAD_DIR, k] = forward(self.roads.odr, p.road, p.lane)
                out[F_ROAD_S, k] = p.s + out[F_ROAD_DIR, k] * self._cx[k]
                out[F_ROAD_T, k] = p.t
                out[F_ROAD_CODE, k] = self.table.code_of(p.road)

    def _map_rows(self, world: WorldState) -> None:
        """Rows of the entities in ``world`` (-1: absent), rebuilt when its ids change."""
        ids = world.ids.tolist()
        if ids != self._ids:
            self._ids = ids
            self._rows = {str(i): k for k, i in enumerate(ids)}
            self._entity_rows = np.array([self._rows.get(n, -1) for n in self.names], np.intp)

    def _snapshot(
        self, world: WorldState, sim: Simulation, view: _View
    ) -> tuple[Snapshot, tuple | None]:
        """What the conditions read now, in arrays reused from step to step (the snapshot
        lives for one evaluation), and the arguments of ``gather_entities`` before its output
        that fills the snapshot's entity arrays in the trigger evaluation's compiled call
        (None: filled here, as entities are located on the map after it)."""
        rows, tb = self._entity_rows, self.table
        if self.bank.needs_road:
            tb.refresh(self.roads.odr)
        present = self._present
        where = GatherArrays(rows, self._centre_offset, view.own, view.driven)
        gather = (_world_arrays(world), tuple(where), tuple(tb.arrays))
        if view.located:
            gather_entities(*gather, tuple(self._fields))
            gather = None
            self._located_road_coords(present)
        if self.bank.needs_road:
            self.bank.link_roads(self.table.road_ids, self.resolver.graph)
        n = len(rows)
        contacts: set[frozenset[int]] = set()
        contact_any = self._no_contact
        # only collision conditions read the contacts
        for col in sim.collisions if self.bank.needs_contacts else ():
            if col.depth <= 0.0:
                continue  # SUMO's per-lane check alone: no sublanes, beside counts as hit
            ia, ib = self.index.get(col.a, -1), self.index.get(col.b, -1)
            for x in (ia, ib):
                if x >= 0:
                    if contact_any is self._no_contact:
                        contact_any = np.zeros(n, dtype=bool)
                    contact_any[x] = True
            if ia >= 0 and ib >= 0:
                contacts.add(frozenset((ia, ib)))
        on_net = self._no_contact  # read only by end-of-road conditions
        if self.bank.needs_on_net:
            on_net = world.lane[np.maximum(rows, 0)] != "" if len(world) else np.zeros(n, bool)
        snap = self._snap
        snap.time, snap.on_net, snap.contacts, snap.contact_any = (
            self.now, on_net, contacts, contact_any
        )  # fmt: skip
        return snap, gather


def _world_arrays(world: WorldState) -> tuple:
    """The WorldState's arrays the snapshot reads, as the kernels take them (a WorldArrays
    as a plain tuple: see kernels.tables)."""
    return tuple(WorldArrays(world.xyz, world.heading, world.speed, world.accel))


__all__ = ["ScenarioEngine", "StepReport", "EntityKind"]
