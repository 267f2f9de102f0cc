"""Actor classes shared by traffic, sensors and risk, their default sizes (the one table) and
their mapping from SUMO vClass."""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum


class ActorClass(IntEnum):
    """Class of a traffic participant, stored as int8 in WorldState.cls."""

    CAR = 0
    TRUCK = 1
    BUS = 2
    MOTORCYCLE = 3
    BICYCLE = 4
    PEDESTRIAN = 5

    @property
    def label(self) -> str:
        """Lower-case name used in files and on the command line."""
        return self.name.lower()

    @property
    def size(self) -> ActorSize:
        """The class's default size (CLASS_SIZE)."""
        return CLASS_SIZE[self]


@dataclass(frozen=True)
class ActorSize:
    """Length (along the heading), width and height of an actor's bounding box, m."""

    length: float
    width: float
    height: float

    def as_tuple(self) -> tuple[float, float, float]:
        """(length, width, height), m."""
        return (self.length, self.width, self.height)


#: Default size per class, m: what demand gives SUMO's vehicle types, what synthetic sensor
#: scenes place, and the size prior of sensors that do not measure size. Cars: a compact car
#: (4.5 m, as NCAP's target cars). Trucks: a medium rigid box truck. Buses: a 12 m low-floor
#: city bus; 3.2 m tall (Mercedes Citaro 3.12 m, Isuzu Erga 3.1 m: SUMO's 3.4 m default is a
#: coach's or a gas bus's). Bicycles and pedestrians: SUMO's defaults (an ordinary city
#: bicycle; an adult's body depth, shoulder width and height, the size the sensor models'
#: detection ranges were calibrated on against the seed's NCAP dummy).
CLASS_SIZE: dict[ActorClass, ActorSize] = {
    ActorClass.CAR: ActorSize(4.5, 1.8, 1.5),
    ActorClass.TRUCK: ActorSize(8.0, 2.5, 3.2),
    ActorClass.BUS: ActorSize(12.0, 2.5, 3.2),
    ActorClass.MOTORCYCLE: ActorSize(2.2, 0.9, 1.5),
    ActorClass.BICYCLE: ActorSize(1.6, 0.65, 1.7),
    ActorClass.PEDESTRIAN: ActorSize(0.215, 0.478, 1.719),
}


_VCLASS_TO_ACTOR: dict[str, ActorClass] = {
    "passenger": ActorClass.CAR,
    "private": ActorClass.CAR,
    "taxi": ActorClass.CAR,
    "emergency": ActorClass.CAR,
    "authority": ActorClass.CAR,
    "army": ActorClass.CAR,
    "vip": ActorClass.CAR,
    "evehicle": ActorClass.CAR,
    "custom1": ActorClass.CAR,
    "custom2": ActorClass.CAR,
    "hov": ActorClass.CAR,
    "delivery": ActorClass.TRUCK,
    "truck": ActorClass.TRUCK,
    "trailer": ActorClass.TRUCK,
    "bus": ActorClass.BUS,
    "coach": ActorClass.BUS,
    "tram": ActorClass.BUS,
    "motorcycle": ActorClass.MOTORCYCLE,
    "moped": ActorClass.MOTORCYCLE,
    "bicycle": ActorClass.BICYCLE,
    "scooter": ActorClass.BICYCLE,
    "pedestrian": ActorClass.PEDESTRIAN,
}


def actor_class_from_vclass(vclass: str) -> ActorClass:
    """Map a SUMO vehicle class name to an ActorClass (unknown classes count as cars)."""
    return _VCLASS_TO_ACTOR.get(vclass, ActorClass.CAR)


def actor_class_from_label(label: str) -> ActorClass:
    """Parse 'car', 'truck', ... into an ActorClass; ValueError names the known labels."""
    try:
        return ActorClass[label.upper()]
    except KeyError:
        known = ", ".join(c.label for c in ActorClass)
        raise ValueError(f"unknown actor class {label!r} (known: {known})") from None
