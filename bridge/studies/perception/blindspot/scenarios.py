"""Each blind-spot combination as a scenario-model Scenario, and its initial world.

Ego in the middle of five lanes at 80 km/h; a truck at the occluder position and a car at the
hidden position, both at the ego's speed, slots SLOT_M apart. One second in, the hidden car
does its motion: cut-in / cut-out (3 s lane change), accelerate (+20 km/h at 2 m/s^2) or
decelerate (to a stop at 6 m/s^2). The run ends after RUN_S.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hiyari.bridge.openscenario.model.actions import (
    AbsoluteSpeed,
    Action,
    Dimension,
    LaneChangeAction,
    RelativeLane,
    Shape,
    SpeedAction,
    TeleportAction,
    TransitionDynamics,
)
from hiyari.bridge.openscenario.model.conditions import (
    Condition,
    Edge,
    Rule,
    SimulationTimeCondition,
)
from hiyari.bridge.openscenario.model.entities import Entity, EntityKind
from hiyari.bridge.openscenario.model.positions import LanePosition
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
from hiyari.bridge.studies.perception.blindspot.catalogue import GRID, Combination, Motion
from hiyari.bridge.studies.perception.blindspot.road import lane_id, pose
from hiyari.sensors.scene.synthetic import actor_world
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState
from hiyari.units import kmh_to_mps

SPEED = float(kmh_to_mps(80.0))
"""Speed of every vehicle at the start, m/s."""
SLOT_M = 25.0
"""Centre-to-centre distance between longitudinal slots, m."""
EGO_S = 150.0
"""Ego station at the start, m."""
MOTION_AT_S = 1.0
RUN_S = 10.0


def _entity(name: str, cls: ActorClass) -> Entity:
    size = cls.size
    return Entity(
        name, EntityKind.VEHICLE, cls, size.length, size.width, size.height,
        centre=(0.0, 0.0, size.height / 2),
    )  # fmt: skip


HIDDEN_SHIFTS_M = tuple(float(x) for x in np.arange(-0.7, 0.51, 0.1) * SLOT_M)
"""Where in its slot the hidden car may start: shifts from the slot centre searched for the
deepest occlusion (the grid's slots are qualitative; the figure with distances is lost)."""
MIN_GAP_M = 1.5
"""Least bumper-to-bumper gap between the hidden car and a truck in the same lane, m."""


def shifts(combo: Combination) -> list[float]:
    """The candidate shifts of ``combo`` that leave the hidden car clear of the truck."""
    (lo, so), (lh, sh) = GRID[combo.occluder], GRID[combo.hidden]
    need = (ActorClass.TRUCK.size.length + ActorClass.CAR.size.length) / 2 + MIN_GAP_M
    return [x for x in HIDDEN_SHIFTS_M if lo != lh or abs((sh - so) * SLOT_M + x) >= need]


def _place(combo: Combination, shift: float = 0.0) -> dict[str, tuple[int, float]]:
    """Entity -> (OpenDRIVE lane, station); the hidden car ``shift`` m from its slot centre."""
    out = {"Ego": (lane_id(0), EGO_S)}
    for name, pos in (("Occluder", combo.occluder), ("Hidden", combo.hidden)):
        lane, slot = GRID[pos]
        extra = shift if name == "Hidden" else 0.0
        out[name] = (lane_id(lane), EGO_S + slot * SLOT_M + extra)
    return out


def initial_world(combo: Combination, shift: float = 0.0) -> WorldState:
    """The scenario's start as a WorldState (ids 'ego', 'occluder', 'hidden'), the hidden car
    ``shift`` m from its slot centre."""
    place = _place(combo, shift)
    actors = []
    for name, cls in (
        ("Ego", ActorClass.CAR),
        ("Occluder", ActorClass.TRUCK),
        ("Hidden", ActorClass.CAR),
    ):
        lane, s = place[name]
        x, y, h = pose(combo.geometry, lane, s)
        actors.append(dict(id=name.lower(), cls=cls, x=x, y=y, heading=h, speed=SPEED))
    return actor_world(actors)


def _motion_action(combo: Combination) -> Action:
    lane, _ = GRID[combo.hidden]
    occ_lane, _ = GRID[combo.occluder]
    match combo.motion:
        case Motion.CUT_IN:
            body = LaneChangeAction(
                TransitionDynamics(Shape.SINUSOIDAL, Dimension.TIME, 3.0),
                RelativeLane("Hidden", -1 if lane > 0 else 1),
            )
        case Motion.CUT_OUT:
            # away from the occluder's side (left when the occluder is in the ego lane)
            body = LaneChangeAction(
                TransitionDynamics(Shape.SINUSOIDAL, Dimension.TIME, 3.0),
                RelativeLane("Hidden", -1 if occ_lane > 0 else 1),
            )
        case Motion.ACCELERATE:
            body = SpeedAction(
                TransitionDynamics(Shape.LINEAR, Dimension.RATE, 2.0),
                AbsoluteSpeed(SPEED + float(kmh_to_mps(20.0))),
            )
        case _:
            body = SpeedAction(
                TransitionDynamics(Shape.LINEAR, Dimension.RATE, 6.0), AbsoluteSpeed(0.0)
            )
    return Action(combo.motion.value, body)


def _at(name: str, seconds: float, edge: Edge = Edge.RISING) -> tuple:
    return ((Condition(name, SimulationTimeCondition(seconds, Rule.GREATER_OR_EQUAL), edge),),)


def build_scenario(combo: Combination, road: Path, shift: float = 0.0) -> Scenario:
    """The scenario of ``combo`` on the OpenDRIVE ``road`` of its geometry, the hidden car
    ``shift`` m from its slot centre."""
    init = []
    for name, (lane, s) in _place(combo, shift).items():
        init.append(InitAction(name, Action("place", TeleportAction(LanePosition("1", lane, s)))))
        init.append(
            InitAction(
                name,
                Action(
                    "speed",
                    SpeedAction(
                        TransitionDynamics(Shape.STEP, Dimension.TIME, 0.0), AbsoluteSpeed(SPEED)
                    ),
                ),
            )
        )
    event = Event("motion", (_motion_action(combo),), _at("go", MOTION_AT_S))
    group = ManeuverGroup("hidden", ("Hidden",), (Maneuver("m", (event,)),))
    story = Story("blind spot", (Act("act", (group,), _at("start", 0.0, Edge.NONE)),))
    return Scenario(
        combo.name,
        (
            _entity("Ego", ActorClass.CAR),
            _entity("Occluder", ActorClass.TRUCK),
            _entity("Hidden", ActorClass.CAR),
        ),
        Storyboard(tuple(init), (story,), _at("end", RUN_S)),
        ego="Ego",
        road_network=road,
    )
