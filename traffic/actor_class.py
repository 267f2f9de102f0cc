"""Actor classes shared by traffic, sensors and risk, and their mapping from SUMO vClass."""

from __future__ import annotations

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
