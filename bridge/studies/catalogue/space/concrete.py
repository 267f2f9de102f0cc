"""Concrete catalogue scenarios: a cell's logical ranges sampled into parameter sets, each
turned into a scenario-model :class:`Scenario` on the generated road.

Entities: "ego" (driven by the ego stack), "actor" (the surrounding vehicle, kinematic,
driven by the storyboard), and for cut-outs from ahead "plus1" (the vehicle the cut-out
reveals: stopped as in Annex G, or slower in a §4.1.3 chain). The actor's manoeuvre starts
at ``Ranges.event_time``. The ego's own lane change is not a storyboard action (the stack
drives the ego): :class:`EgoLaneChange` says when and where, and the runner commands it.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field

from hiyari.bridge.openscenario.model import (
    AbsoluteLane,
    AbsoluteSpeed,
    Act,
    Action,
    Condition,
    Dimension,
    Entity,
    EntityKind,
    Event,
    InitAction,
    LaneChangeAction,
    LanePosition,
    Maneuver,
    ManeuverGroup,
    Rule,
    Scenario,
    Shape,
    SimulationTimeCondition,
    SpeedAction,
    Story,
    Storyboard,
    TeleportAction,
    TransitionDynamics,
)
from hiyari.bridge.studies.catalogue.space.layout import BEHIND, MotorwayLayout
from hiyari.bridge.studies.catalogue.space.obstruction import Cell
from hiyari.bridge.studies.catalogue.space.parameters import Ranges, sample
from hiyari.bridge.studies.catalogue.space.sketch import (
    ACCEL_SPAN,
    EGO_SIZE,
    OTHER_SIZE,
    SWERVE_SHIFT,
)
from hiyari.bridge.studies.catalogue.space.taxonomy import Geometry, Motion, Position
from hiyari.errors import HiyariError
from hiyari.net.road.xodr_writer import MAIN_ROAD
from hiyari.traffic.actor_class import ActorClass


@dataclass(frozen=True)
class EgoLaneChange:
    """The ego's lane change: at ``time`` s into OpenDRIVE lane ``lane`` of road ``road`` at
    ``lateral_speed`` m/s."""

    time: float
    road: str
    lane: int
    lateral_speed: float


@dataclass(frozen=True)
class ConcreteCase:
    """One concrete run of a cell: ``run_id`` is the stable row key of the results table."""

    cell: Cell
    index: int
    params: dict[str, float]
    seed: int
    ranges: Ranges = field(default_factory=Ranges)

    @property
    def run_id(self) -> str:
        return f"{self.cell.key}-{self.index:03d}"

    @property
    def layout(self) -> MotorwayLayout:
        c = self.cell.combination
        return MotorwayLayout(c.geometry, c.ego, self.cell.lanes)

    @property
    def has_plus_one(self) -> bool:
        return self.cell.combination.motion == Motion.CUT_OUT and self.cell.position not in BEHIND

    def ego_lane_change(self) -> EgoLaneChange | None:
        """The ego's own lane change (None when it keeps its lane)."""
        lay = self.layout
        if lay.ego_target == lay.ego_lane:
            return None
        r = self.ranges
        return EgoLaneChange(r.ego_event_time, MAIN_ROAD, lay.ego_target, r.ego_lateral_speed)


def cell_seed(cell: Cell, seed: int) -> int:
    """A per-cell seed that does not depend on which other cells run."""
    return (zlib.crc32(cell.key.encode()) ^ seed) & 0x7FFFFFFF


def concrete_cases(
    cell: Cell, n: int, seed: int = 0, ranges: Ranges | None = None
) -> list[ConcreteCase]:
    """``n`` concrete cases of a valid motorway ``cell`` sampled from its logical ranges."""
    ranges = ranges or Ranges()
    if not cell.valid:
        raise HiyariError(f"cell {cell.key} is not evaluated ({cell.status}: {cell.reason})")
    if cell.combination.geometry == Geometry.INTERSECTION:
        raise HiyariError(f"cell {cell.key}: intersection runs are not supported yet")
    c = cell.combination
    names = ranges.names(c.motion.value, cell.position == Position.FRONT, c.prefix == "C")
    s = cell_seed(cell, seed)
    rows = sample(ranges, names, cell.position in BEHIND, n, s)
    return [ConcreteCase(cell, i, p, s + i, ranges) for i, p in enumerate(rows)]


def _vehicle(name: str, size: tuple[float, float]) -> Entity:
    return Entity(name, EntityKind.VEHICLE, ActorClass.CAR, size[0], size[1], 1.5)


def _start(case: ConcreteCase) -> tuple[int, float, float]:
    """The actor's lane, reference station (box centre, m) and speed (m/s)."""
    lay, p, pos = case.layout, case.params, case.cell.position
    lane = lay.lane_of(pos)
    ve = p["ego_speed"]
    gap = p["lead_thw"] * ve if "lead_thw" in p else p["gap"]
    half = 0.5 * (EGO_SIZE[0] + OTHER_SIZE[0])
    s = lay.start - half - gap if pos in BEHIND else lay.start + half + gap
    return lane, s, max(ve + p.get("speed_delta", 0.0), 0.5)


def _at(name: str, when: float, action: Action) -> Event:
    cond = Condition(f"{name}_time", SimulationTimeCondition(when, Rule.GREATER_THAN))
    return Event(name, (action,), ((cond,),))


def _manoeuvre(case: ConcreteCase, v0: float) -> Action | None:
    p, motion = case.params, case.cell.combination.motion
    if motion == Motion.ACCELERATE:
        dyn = TransitionDynamics(Shape.LINEAR, Dimension.RATE, p["accel"])
        return Action("accelerate", SpeedAction(dyn, AbsoluteSpeed(v0 + ACCEL_SPAN)))
    if motion == Motion.DECELERATE:
        dyn = TransitionDynamics(Shape.LINEAR, Dimension.RATE, p["decel"])
        return Action("decelerate", SpeedAction(dyn, AbsoluteSpeed(0.0)))
    target, _ = case.layout.target_lane(case.cell.position, motion)
    if target is None:
        return None
    dyn = TransitionDynamics(Shape.LINEAR, Dimension.RATE, p["lateral_speed"])
    offset = 0.0
    if motion == Motion.SWERVE:  # within its lane, toward the ego's (left when in it)
        lay = case.layout
        toward = lay.centre_t(lay.ego_lane) - lay.centre_t(target)
        offset = SWERVE_SHIFT if toward >= 0 else -SWERVE_SHIFT
    return Action(motion.value, LaneChangeAction(dyn, AbsoluteLane(target), offset))


def to_scenario(case: ConcreteCase) -> Scenario:
    """The concrete case as a scenario-model Scenario on its generated road (road "main")."""
    lay, p = case.layout, case.params
    ve = p["ego_speed"]
    lane, s, v0 = _start(case)
    entities = [_vehicle("ego", EGO_SIZE), _vehicle("actor", OTHER_SIZE)]

    def place(name: str, ln: int, st: float, v: float) -> list[InitAction]:
        at = LanePosition(MAIN_ROAD, ln, st)
        step = TransitionDynamics(Shape.STEP, Dimension.TIME, 0.0)
        return [
            InitAction(name, Action(f"{name}_place", TeleportAction(at))),
            InitAction(name, Action(f"{name}_speed", SpeedAction(step, AbsoluteSpeed(v)))),
        ]

    init = place("ego", lay.ego_lane, lay.start, ve) + place("actor", lane, s, v0)
    if case.has_plus_one:
        entities.append(_vehicle("plus1", OTHER_SIZE))
        s1 = s + OTHER_SIZE[0] + p["plus_one_gap"]
        init += place("plus1", lane, s1, p.get("plus_one_speed", 0.0) * ve)
    action = _manoeuvre(case, v0)
    events = () if action is None else (_at("manoeuvre", case.ranges.event_time, action),)
    story = Story(
        "disturbance",
        (Act("act", (ManeuverGroup("actor", ("actor",), (Maneuver("m", events),)),)),),
    )
    stop = ((Condition("end", SimulationTimeCondition(case.ranges.duration, Rule.GREATER_THAN)),),)
    return Scenario(
        name=case.run_id,
        entities=tuple(entities),
        storyboard=Storyboard(tuple(init), (story,), stop),
        ego="ego",
        parameters={k: v for k, v in p.items()},
    )
