"""Trigger conditions: by value (time, storyboard states, parameters) and by entity
(distances, headway, TTC, speeds, position, end of road, collision). SI units."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from hiyari.bridge.openscenario.model.positions import Position

__all__ = [
    "AccelerationCondition",
    "AngleCondition",
    "CollisionCondition",
    "Condition",
    "ConditionBody",
    "ConditionGroup",
    "CoordinateSystem",
    "DistanceCondition",
    "DistanceType",
    "Edge",
    "EndOfRoadCondition",
    "EntityCondition",
    "EntityConditionBody",
    "OffroadCondition",
    "ParameterCondition",
    "ReachPositionCondition",
    "RelativeAngleCondition",
    "RelativeClearanceCondition",
    "RelativeDistanceCondition",
    "RelativeSpeedCondition",
    "Rule",
    "SimulationTimeCondition",
    "SpeedCondition",
    "StandStillCondition",
    "StoryboardElementStateCondition",
    "TimeHeadwayCondition",
    "TimeOfDayCondition",
    "TimeToCollisionCondition",
    "TrafficSignalCondition",
    "TrafficSignalControllerCondition",
    "TraveledDistanceCondition",
    "Trigger",
    "VariableCondition",
]


class Rule(StrEnum):
    """Comparison of a measured value with the condition's value."""

    GREATER_THAN = "greaterThan"
    LESS_THAN = "lessThan"
    EQUAL_TO = "equalTo"
    GREATER_OR_EQUAL = "greaterOrEqual"
    LESS_OR_EQUAL = "lessOrEqual"
    NOT_EQUAL_TO = "notEqualTo"


class Edge(StrEnum):
    """When a condition counts as true: whenever its value is true (none), or only at the step
    where the value turns true (rising), false (falling), or either."""

    RISING = "rising"
    FALLING = "falling"
    RISING_OR_FALLING = "risingOrFalling"
    NONE = "none"


class DistanceType(StrEnum):
    """Which component of a distance: along the reference's x axis, across it, or straight."""

    LONGITUDINAL = "longitudinal"
    LATERAL = "lateral"
    EUCLIDEAN = "euclidianDistance"


class CoordinateSystem(StrEnum):
    """The frame a distance is measured in: the reference entity's axes, road coordinates
    (s along the road, t across it), lane coordinates (along the lane's centre line, across
    in lanes), trajectory coordinates (along and across the triggering entity's trajectory),
    or the world's x and y axes."""

    ENTITY = "entity"
    ROAD = "road"
    LANE = "lane"
    TRAJECTORY = "trajectory"
    WORLD = "world"


@dataclass(frozen=True)
class SimulationTimeCondition:
    """Simulation time (s) compared with ``value``."""

    value: float
    rule: Rule


@dataclass(frozen=True)
class StoryboardElementStateCondition:
    """A storyboard element (``element_type``: story, act, maneuverGroup, maneuver, event,
    action) is in ``state`` (standbyState, runningState, completeState) or went through a
    transition (startTransition, endTransition, stopTransition, skipTransition) at the last
    update."""

    element_type: str
    element: str
    state: str


@dataclass(frozen=True)
class ParameterCondition:
    """Parameter ``parameter`` compared with ``value`` (numbers numerically, else as text)."""

    parameter: str
    value: str
    rule: Rule


@dataclass(frozen=True)
class VariableCondition:
    """Variable ``variable`` compared with ``value`` (numbers numerically, else as text)."""

    variable: str
    value: str
    rule: Rule


@dataclass(frozen=True)
class TimeOfDayCondition:
    """The scenario's time of day (its EnvironmentAction's, running on with the simulation
    when animated) compared with ``date_time`` (ISO 8601 text)."""

    date_time: str
    rule: Rule


@dataclass(frozen=True)
class TrafficSignalCondition:
    """Traffic signal ``signal`` (a SUMO traffic light) shows ``state`` (as in
    TrafficSignalStateAction)."""

    signal: str
    state: str


@dataclass(frozen=True)
class TrafficSignalControllerCondition:
    """Controller ``controller`` (a SUMO traffic light) is in phase ``phase`` (name or
    index)."""

    controller: str
    phase: str


@dataclass(frozen=True)
class RelativeDistanceCondition:
    """Distance from each triggering entity to ``entity`` compared with ``value`` (m).
    ``freespace``: between bounding boxes, else between reference points."""

    entity: str
    distance_type: DistanceType
    value: float
    freespace: bool
    rule: Rule
    coordinate_system: CoordinateSystem = CoordinateSystem.ENTITY


@dataclass(frozen=True)
class DistanceCondition:
    """Distance from each triggering entity to ``position`` compared with ``value`` (m)."""

    position: Position
    distance_type: DistanceType
    value: float
    freespace: bool
    rule: Rule
    coordinate_system: CoordinateSystem = CoordinateSystem.ENTITY


@dataclass(frozen=True)
class ReachPositionCondition:
    """A triggering entity's reference point is within ``tolerance`` m of ``position``."""

    position: Position
    tolerance: float


@dataclass(frozen=True)
class TimeHeadwayCondition:
    """Time headway (gap to ``entity`` / own speed, s) compared with ``value``; infinite
    while standing or when ``entity`` is behind."""

    entity: str
    value: float
    freespace: bool
    rule: Rule
    coordinate_system: CoordinateSystem = CoordinateSystem.ENTITY
    distance_type: DistanceType = DistanceType.LONGITUDINAL


@dataclass(frozen=True)
class TimeToCollisionCondition:
    """Time to collision with ``entity`` (or with ``position``, a fixed point), s: the gap
    over the closing speed along the measured direction; infinite when not closing."""

    value: float
    freespace: bool
    rule: Rule
    entity: str | None = None
    position: Position | None = None
    coordinate_system: CoordinateSystem = CoordinateSystem.ENTITY
    distance_type: DistanceType = DistanceType.EUCLIDEAN


@dataclass(frozen=True)
class SpeedCondition:
    """Speed (m/s) compared with ``value``: the total speed (the velocity's magnitude,
    positive when reversing), or with ``direction`` (longitudinal, lateral, vertical: the
    entity's axes) the velocity's signed component along that axis."""

    value: float
    rule: Rule
    direction: str | None = None


@dataclass(frozen=True)
class RelativeSpeedCondition:
    """Own speed minus ``entity``'s (m/s) compared with ``value``; with ``direction``
    (longitudinal, lateral, vertical) the component of the relative velocity (own minus
    ``entity``'s) along that axis of the triggering entity."""

    entity: str
    value: float
    rule: Rule
    direction: str | None = None


@dataclass(frozen=True)
class AccelerationCondition:
    """Acceleration (m/s^2) compared with ``value``: the total acceleration (the magnitude of
    the acceleration vector, never negative), or with ``direction`` its signed component:
    longitudinal along the heading, lateral across it (the speed times the yaw rate,
    positive to the left), vertical along the entity's up axis."""

    value: float
    rule: Rule
    direction: str | None = None


@dataclass(frozen=True)
class StandStillCondition:
    """Standing (speed below 0.01 m/s) for at least ``duration`` s."""

    duration: float


@dataclass(frozen=True)
class TraveledDistanceCondition:
    """The distance travelled since the scenario started (m, the integral of the speed's
    magnitude) is at least ``value``."""

    value: float


@dataclass(frozen=True)
class EndOfRoadCondition:
    """Off every road (no SUMO lane under the reference point) for at least ``duration`` s."""

    duration: float


@dataclass(frozen=True)
class OffroadCondition:
    """Off every road (no lane of the network under the reference point) for at least
    ``duration`` s."""

    duration: float


@dataclass(frozen=True)
class RelativeClearanceCondition:
    """No other entity (only ``entities`` when given) in the lanes ``lanes`` (ranges of lanes
    relative to the triggering entity's, 0 its own, positive to its left; all lanes when
    empty) from ``backward`` m behind to ``forward`` m ahead of it along the road; lanes of
    the opposite direction count only with ``opposite``; ``freespace``: between the boxes,
    else the reference points."""

    opposite: bool
    freespace: bool
    forward: float = 0.0
    backward: float = 0.0
    lanes: tuple[tuple[int, int], ...] = ()
    entities: tuple[str, ...] = ()


@dataclass(frozen=True)
class AngleCondition:
    """The entity's ``angle_type`` angle (heading; pitch and roll are 0: hiyari's actors are
    level) is ``angle`` within ``tolerance`` (rad): in the world (coordinate system entity),
    or relative to the road's direction of travel there (road, lane)."""

    angle_type: str
    angle: float
    tolerance: float
    coordinate_system: CoordinateSystem = CoordinateSystem.ENTITY


@dataclass(frozen=True)
class RelativeAngleCondition:
    """The entity's ``angle_type`` angle relative to ``entity``'s is ``angle`` within
    ``tolerance`` (rad)."""

    entity: str
    angle_type: str
    angle: float
    tolerance: float


@dataclass(frozen=True)
class CollisionCondition:
    """In contact with ``entity``, or with any object of type ``by_type`` (vehicle,
    pedestrian, miscellaneous; SUMO's own traffic included), else with anything."""

    entity: str | None = None
    by_type: str | None = None


EntityConditionBody = (
    RelativeDistanceCondition
    | DistanceCondition
    | ReachPositionCondition
    | TimeHeadwayCondition
    | TimeToCollisionCondition
    | SpeedCondition
    | RelativeSpeedCondition
    | AccelerationCondition
    | StandStillCondition
    | TraveledDistanceCondition
    | EndOfRoadCondition
    | OffroadCondition
    | RelativeClearanceCondition
    | AngleCondition
    | RelativeAngleCondition
    | CollisionCondition
)


@dataclass(frozen=True)
class EntityCondition:
    """``body`` holds for "any" or "all" of the ``triggering`` entities."""

    triggering: tuple[str, ...]
    rule: str
    body: EntityConditionBody


ConditionBody = (
    SimulationTimeCondition
    | StoryboardElementStateCondition
    | ParameterCondition
    | VariableCondition
    | TrafficSignalCondition
    | TrafficSignalControllerCondition
    | TimeOfDayCondition
    | EntityCondition
)


@dataclass(frozen=True)
class Condition:
    """A named condition with its edge and delay (s)."""

    name: str
    body: ConditionBody
    edge: Edge = Edge.NONE
    delay: float = 0.0
    source: str = ""


ConditionGroup = tuple[Condition, ...]  # all must hold
Trigger = tuple[ConditionGroup, ...]  # any group must hold; () = no trigger
