"""Scenario entities: the ego, vehicles, pedestrians and stationary objects, with sizes."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from hiyari.traffic.actor_class import ActorClass

__all__ = ["ControllerSpec", "Entity", "EntityKind"]


class EntityKind(StrEnum):
    """What SUMO makes of an entity: a vehicle, a person, or a fixed object (a vehicle that
    never moves)."""

    VEHICLE = "vehicle"
    PEDESTRIAN = "pedestrian"
    MISC = "misc"


@dataclass(frozen=True)
class ControllerSpec:
    """A controller named in the scenario (ObjectController / AssignControllerAction).

    ``drives`` says who moves the entity while the controller is active: "stack" (the ego
    stack under test: hiyari's or a user's) or "storyboard" (the storyboard's actions). A file
    asks for the storyboard with the controller property ``hiyari:driver = storyboard``.
    """

    name: str
    properties: dict[str, str] = field(default_factory=dict)

    @property
    def drives(self) -> str:
        """'stack' or 'storyboard'."""
        return "storyboard" if self.properties.get("hiyari:driver") == "storyboard" else "stack"


@dataclass(frozen=True)
class Entity:
    """One scenario object. Sizes in metres; ``centre`` is the bounding-box centre relative to
    the entity's reference point (x forward, y left, z up; OpenSCENARIO vehicles: the rear
    axle), so positions in the scenario refer to the reference point and the WorldState to the
    box centre. Speeds m/s, accelerations m/s^2 (None: not limited by the file)."""

    name: str
    kind: EntityKind
    actor_class: ActorClass
    length: float
    width: float
    height: float
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)
    category: str = ""  # the file's vehicleCategory / pedestrianCategory / miscObjectCategory
    max_speed: float | None = None
    max_accel: float | None = None
    max_decel: float | None = None
    controller: ControllerSpec | None = None
    properties: dict[str, str] = field(default_factory=dict)
    #: Every ObjectController of the entity (``controller`` is the first: assigned at the
    #: start), by its ObjectController name, else its Controller's name.
    controllers: dict[str, ControllerSpec] = field(default_factory=dict)
