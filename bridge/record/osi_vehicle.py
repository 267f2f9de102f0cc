"""OSI ``MovingObject.VehicleAttributes`` of a vehicle from its class and bounding box: axles,
wheels and ground clearance, and the OSI vehicle frame they define.

hiyari's vehicles are boxes (WorldState: length, width, height; the ray-cast shapes of
:mod:`hiyari.sensors.scene.actor_shapes`); they have no modelled axles. The axle layout per
class below is a toolkit table of typical vehicles, as shares of the box so that it scales
with each vehicle's size; the ground clearance is the lowest point of the class's ray-cast
body. OSI's vehicle frame (DIN ISO 8855: x forward, y left, z up) has its origin at the
middle of the rear axle, ``base.position + R bbcenter_to_rear``; sensor mounting positions
are given in that frame, while hiyari's sensor mounts are given from the centre of the
vehicle's ground rectangle (:func:`rear_axle`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from osi3.osi_object_pb2 import MovingObject

from hiyari.sensors.scene.actor_shapes import TEMPLATES
from hiyari.traffic.actor_class import ActorClass


@dataclass(frozen=True)
class AxleLayout:
    """Two axles in a vehicle's box, as shares of its length, width and height."""

    front_overhang: float
    """Front end to front axle, share of the length."""
    rear_overhang: float
    """Rear end to rear axle, share of the length."""
    wheel_radius: float
    """Wheel centre above the ground (tyre radius), share of the height."""
    track: float
    """Between the wheel centres of an axle, share of the width (0: one wheel per axle)."""
    tyre_width: float
    """Share of the width."""


#: Typical vehicles of each class (toolkit choice from published dimensions): a compact car
#: (4.3-4.5 m hatchback: wheelbase 0.61 L, front overhang 0.21 L, rear 0.18 L, 205/55 R16
#: tyres, 1.55 m track), a medium rigid truck (8 m, 4.6 m wheelbase), a 12 m city bus (5.9 m
#: wheelbase, 2.8 m front overhang), a motorcycle (1.45 m wheelbase) and a city bicycle
#: (1.05 m wheelbase, 700c wheels). Other vehicle classes take the car's.
AXLES: dict[ActorClass, AxleLayout] = {
    ActorClass.CAR: AxleLayout(0.21, 0.18, 0.21, 0.86, 0.11),
    ActorClass.TRUCK: AxleLayout(0.16, 0.27, 0.14, 0.80, 0.10),
    ActorClass.BUS: AxleLayout(0.23, 0.28, 0.15, 0.84, 0.11),
    ActorClass.MOTORCYCLE: AxleLayout(0.18, 0.16, 0.20, 0.0, 0.17),
    ActorClass.BICYCLE: AxleLayout(0.18, 0.16, 0.20, 0.0, 0.05),
}


def _class(cls: int) -> ActorClass:
    """The actor class of a WorldState ``cls`` value (a car for an unknown value)."""
    try:
        return ActorClass(cls)
    except ValueError:
        return ActorClass.CAR


def _layout(cls: int) -> AxleLayout:
    return AXLES.get(_class(cls), AXLES[ActorClass.CAR])


def ground_clearance(cls: int, height: float) -> float:
    """Ground to the lowest point of the class's ray-cast body, m."""
    return float(TEMPLATES[_class(cls)].vertices[:, 2].min()) * height


def axle_vectors(cls: int, length: float, height: float) -> tuple[np.ndarray, np.ndarray]:
    """(bbcenter_to_rear, bbcenter_to_front): box centre to the middle of the rear / front
    axle at wheel-centre height, vehicle frame, m."""
    a = _layout(cls)
    z = a.wheel_radius * height - 0.5 * height
    rear = np.array([-0.5 * length + a.rear_overhang * length, 0.0, z])
    front = np.array([0.5 * length - a.front_overhang * length, 0.0, z])
    return rear, front


def rear_axle(cls: int, length: float, height: float) -> np.ndarray:
    """Middle of the rear axle (the OSI vehicle frame's origin) in hiyari's vehicle frame
    (origin at the centre of the ground rectangle), m."""
    rear, _ = axle_vectors(cls, length, height)
    return rear + [0.0, 0.0, 0.5 * height]


def vehicle_attributes(
    cls: int, length: float, width: float, height: float
) -> MovingObject.VehicleAttributes:
    """The VehicleAttributes of a vehicle of class ``cls`` and box ``length`` x ``width`` x
    ``height`` m: axle vectors, ground clearance, number of wheels and each wheel's axle,
    index (right to left), centre, radius and tyre width."""
    a = _layout(cls)
    rear, front = axle_vectors(cls, length, height)
    va = MovingObject.VehicleAttributes()
    va.bbcenter_to_rear.x, va.bbcenter_to_rear.y, va.bbcenter_to_rear.z = rear.tolist()
    va.bbcenter_to_front.x, va.bbcenter_to_front.y, va.bbcenter_to_front.z = front.tolist()
    va.ground_clearance = ground_clearance(cls, height)
    sides = (-0.5 * a.track * width, 0.5 * a.track * width) if a.track > 0 else (0.0,)
    va.number_wheels = 2 * len(sides)
    for axle, centre in enumerate((front, rear)):  # OSI: axle 0 is the front-most
        for index, y in enumerate(sides):
            w = va.wheel_data.add(axle=axle, index=index)
            w.position.x, w.position.y, w.position.z = float(centre[0]), y, float(centre[2])
            w.wheel_radius = a.wheel_radius * height
            w.width = a.tyre_width * width
    return va
