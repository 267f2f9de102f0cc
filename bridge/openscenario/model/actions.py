"""Storyboard actions on entities. SI units: m, s, m/s, m/s^2, rad."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from hiyari.bridge.openscenario.model.entities import ControllerSpec
from hiyari.bridge.openscenario.model.global_actions import GlobalActionBody
from hiyari.bridge.openscenario.model.positions import Position
from hiyari.bridge.openscenario.model.trajectories import Route, Trajectory

__all__ = [
    "AbsoluteLane",
    "AbsoluteOffset",
    "AbsoluteSpeed",
    "AcquirePositionAction",
    "Action",
    "ActionBody",
    "ActivateControllerAction",
    "AssignControllerAction",
    "AssignRouteAction",
    "Dimension",
    "FollowTrajectoryAction",
    "LaneChangeAction",
    "LaneOffsetAction",
    "LightStateAction",
    "LateralDistanceAction",
    "LongitudinalDistanceAction",
    "RandomRouteAction",
    "RelativeLane",
    "RelativeOffset",
    "RelativeSpeed",
    "Shape",
    "SpeedAction",
    "SpeedProfileAction",
    "SynchronizeAction",
    "TeleportAction",
    "Timing",
    "TransitionDynamics",
    "VisibilityAction",
]


class Shape(StrEnum):
    """How a value moves from its start to its target over a transition (x in [0, 1]):
    step (at once), linear x, cubic 3x^2 - 2x^3, sinusoidal (1 - cos(pi x)) / 2."""

    STEP = "step"
    LINEAR = "linear"
    CUBIC = "cubic"
    SINUSOIDAL = "sinusoidal"


class Dimension(StrEnum):
    """What a transition's ``value`` measures: its duration (s), the distance travelled
    during it (m), or its rate of change (per second; the peak rate for curved shapes)."""

    TIME = "time"
    DISTANCE = "distance"
    RATE = "rate"


@dataclass(frozen=True)
class TransitionDynamics:
    """Shape and size of a transition (OpenSCENARIO TransitionDynamics)."""

    shape: Shape
    dimension: Dimension
    value: float


@dataclass(frozen=True)
class AbsoluteSpeed:
    """Target speed, m/s."""

    value: float


@dataclass(frozen=True)
class RelativeSpeed:
    """Target speed relative to ``entity``: its speed + value ("delta", m/s) or times value
    ("factor"); ``continuous``: keep tracking it after the transition."""

    entity: str
    value: float
    kind: str = "delta"
    continuous: bool = False


@dataclass(frozen=True)
class SpeedAction:
    """Change the speed along the path to ``target`` with ``dynamics``."""

    dynamics: TransitionDynamics
    target: AbsoluteSpeed | RelativeSpeed


@dataclass(frozen=True)
class LongitudinalDistanceAction:
    """Put the actor at a gap (``distance`` m, or ``time_gap`` s times the reference's speed)
    ahead of ("leadingReferencedEntity") or behind ("trailingReferencedEntity") ``entity``
    along the road ("any": on the side it is on), bumper to bumper when ``freespace``; ``continuous`` keeps that gap.
    With ``limits`` (DynamicConstraints: max acceleration, deceleration m/s^2, max speed
    m/s; None each where not given) the actor drives there (a critically damped follower
    within the limits) instead of being put there. The gap is measured in
    ``coordinate_system``: "entity" along the reference's heading (x axis), "road" along the
    road's s, "lane" along the centre line of the reference's lane."""

    entity: str
    distance: float | None
    time_gap: float | None
    freespace: bool
    continuous: bool
    displacement: str = "trailingReferencedEntity"
    limits: tuple[float | None, float | None, float | None] | None = None
    coordinate_system: str = "entity"


@dataclass(frozen=True)
class SpeedProfileAction:
    """Speeds to reach one after the other: ``entries`` of (speed m/s, time s or None); with
    ``entity`` the speeds are added to that entity's speed at the start. A time is how long
    reaching that speed takes (linearly); without one the change takes as long as
    ``max_accel`` / ``max_decel`` (m/s^2) allow (at once when they are not given).
    ``following_mode`` "follow" also keeps a timed change within those limits (it then takes
    longer) and, with ``max_accel_rate`` / ``max_decel_rate`` (m/s^3, the jerk limits),
    changes the acceleration no faster than they allow (the speed then rounds the
    profile's corners); "position" follows the times exactly. ``max_speed`` caps every
    speed."""

    entries: tuple[tuple[float, float | None], ...]
    following_mode: str = "follow"
    entity: str | None = None
    max_accel: float | None = None
    max_decel: float | None = None
    max_speed: float | None = None
    max_accel_rate: float | None = None
    max_decel_rate: float | None = None


@dataclass(frozen=True)
class SynchronizeAction:
    """Reach ``target`` when the ``master`` entity reaches ``master_target`` (each within its
    tolerance, m), adjusting only the actor's speed. ``final_speed`` (m/s; None: not
    given): absolute, or with ``final_relative`` "delta" / "factor" relative to the master's
    speed; ``steady_distance`` m (or ``steady_time`` s) before the target the actor is at
    the final speed and holds it."""

    master: str
    master_target: Position
    target: Position
    final_speed: float | None = None
    final_relative: str = ""
    steady_distance: float | None = None
    steady_time: float | None = None
    master_tolerance: float = 0.0
    tolerance: float = 0.0


@dataclass(frozen=True)
class AbsoluteLane:
    """Target lane by OpenDRIVE lane id."""

    lane: int


@dataclass(frozen=True)
class RelativeLane:
    """Target lane ``value`` lanes to the left (driving direction) of ``entity``'s lane."""

    entity: str
    value: int


@dataclass(frozen=True)
class LaneChangeAction:
    """Move to the ``target`` lane's centre (+ ``target_offset`` m) with ``dynamics`` (time:
    duration s; distance: along the road m; rate: peak lateral speed m/s)."""

    dynamics: TransitionDynamics
    target: AbsoluteLane | RelativeLane
    target_offset: float = 0.0


@dataclass(frozen=True)
class AbsoluteOffset:
    """Target offset from the lane centre, m (road t direction)."""

    value: float


@dataclass(frozen=True)
class RelativeOffset:
    """Target offset = ``entity``'s lane offset + ``value``, m."""

    entity: str
    value: float


@dataclass(frozen=True)
class LaneOffsetAction:
    """Shift to a lateral offset within the lane with ``shape`` and peak lateral acceleration
    ``max_lateral_acc`` (m/s^2); ``continuous`` keeps it (and follows a relative target)."""

    target: AbsoluteOffset | RelativeOffset
    shape: Shape
    max_lateral_acc: float
    continuous: bool = False


@dataclass(frozen=True)
class LateralDistanceAction:
    """Hold the actor ``distance`` m across the road from ``entity`` (between the boxes'
    sides when ``freespace``, else between the reference points), on the side
    ``displacement`` says (leftToReferencedEntity, rightToReferencedEntity: in the
    reference's direction of travel; any: the side it is on). ``continuous``: hold it
    every step (the reference may move across), and the action runs until it is stopped.
    ``limits``: the DynamicConstraints, lateral (maximum acceleration, deceleration m/s^2,
    maximum speed m/s; None each where not given; None: no DynamicConstraints, the actor is
    put there at once)."""

    entity: str
    distance: float
    freespace: bool
    continuous: bool
    displacement: str = "any"
    limits: tuple[float | None, float | None, float | None] | None = None


@dataclass(frozen=True)
class VisibilityAction:
    """Whether the entity is seen: by renderers (``graphics``), by other traffic
    (``traffic``), by the ego's sensors (``sensors``)."""

    graphics: bool
    traffic: bool
    sensors: bool


@dataclass(frozen=True)
class LightStateAction:
    """Set light ``light`` (a vehicleLightType such as brakeLights, or a user-defined light's
    name) to ``mode`` (on, off, flashing)."""

    light: str
    mode: str
    user_defined: bool = False


@dataclass(frozen=True)
class TeleportAction:
    """Place the actor at ``position`` now."""

    position: Position


@dataclass(frozen=True)
class Timing:
    """How vertex times map to simulation time: absolute (t_sim = scale * t + offset) or
    relative to the action's start."""

    absolute: bool
    scale: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class FollowTrajectoryAction:
    """Follow ``trajectory``; with ``timing`` its times set where the actor is when (both
    domains), without it the actor moves along it at the speed its longitudinal actions give
    (the lateral domain only). ``following_mode``: "position" or "follow" (a scripted actor
    follows exactly either way); ``initial_distance_offset``: m along the trajectory where
    the actor starts."""

    trajectory: Trajectory
    timing: Timing | None
    following_mode: str = "position"
    initial_distance_offset: float = 0.0


@dataclass(frozen=True)
class AssignRouteAction:
    """Drive / walk through ``waypoints`` in order at the actor's speed, along the roads (the
    shortest way by road length) keeping its lateral place on them; straight lines where no
    road connects two waypoints."""

    name: str
    waypoints: tuple[Position, ...]
    closed: bool = False

    @property
    def route(self) -> Route:
        """The route assigned."""
        return Route(self.name, self.waypoints, self.closed)


@dataclass(frozen=True)
class RandomRouteAction:
    """Drive to a destination drawn at random along the roads ahead (about 1 km on, through
    junctions chosen at random; repeatable: drawn from the actor's name)."""


@dataclass(frozen=True)
class AcquirePositionAction:
    """Go to ``position`` at the actor's speed (a route from where it is)."""

    position: Position


@dataclass(frozen=True)
class AssignControllerAction:
    """Give the actor ``controller`` and activate it in the given domains (None: unchanged)."""

    controller: ControllerSpec
    lateral: bool | None = None
    longitudinal: bool | None = None


@dataclass(frozen=True)
class ActivateControllerAction:
    """Switch the actor's assigned controller on (True) or off (False) per domain;
    ``controller``: the name of one of the entity's ObjectControllers to make the assigned
    one first (None: keep the assigned one)."""

    lateral: bool | None = None
    longitudinal: bool | None = None
    controller: str | None = None


ActionBody = (
    SpeedAction
    | SpeedProfileAction
    | SynchronizeAction
    | LongitudinalDistanceAction
    | LaneChangeAction
    | LaneOffsetAction
    | LateralDistanceAction
    | VisibilityAction
    | LightStateAction
    | TeleportAction
    | FollowTrajectoryAction
    | AssignRouteAction
    | AcquirePositionAction
    | RandomRouteAction
    | AssignControllerAction
    | ActivateControllerAction
)


@dataclass(frozen=True)
class Action:
    """A named storyboard action (``source``: file:line it came from, for messages): a private
    action (run on each actor of its maneuver group) or a global one (run once)."""

    name: str
    body: ActionBody | GlobalActionBody
    source: str = ""
