"""LateralDistanceAction: where across the road the actor is to be, relative to its reference
entity (road t, metres, positive to the left of the reference line), and how fast it gets
there within the action's DynamicConstraints (lateral acceleration, deceleration and speed)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from hiyari.bridge.openscenario.model.actions import LateralDistanceAction
from hiyari.errors import HiyariError

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine


def lateral_goal(engine: ScenarioEngine, actor: str, b: LateralDistanceAction) -> float:
    """Road t (m) at which ``actor`` is ``b.distance`` across from ``b.entity`` on the side
    ``b.displacement`` gives ("any": the side it is on now)."""
    ref, me = engine.road_pose(b.entity), engine.road_pose(actor)
    if not ref.road or ref.road != me.road:
        raise HiyariError(f"LateralDistanceAction: {actor!r} and {b.entity!r} are not on one road")
    gap = b.distance
    if b.freespace:
        gap += 0.5 * (engine.actors[actor].entity.width + engine.actors[b.entity].entity.width)
    left = engine.travel_direction(b.entity)  # +t is the reference's left when it drives +s
    if b.displacement == "leftToReferencedEntity":
        side = left
    elif b.displacement == "rightToReferencedEntity":
        side = -left
    else:
        side = 1.0 if me.t >= ref.t else -1.0
    return ref.t + side * gap


def limited(b: LateralDistanceAction) -> bool:
    """Whether the action gives any lateral limit (else the actor is put at its goal)."""
    return b.limits is not None and any(x is not None and x > 0 for x in b.limits)


def sinusoidal_duration(b: LateralDistanceAction, change: float) -> float:
    """Duration (s) of a sinusoidal move of ``change`` m whose peak lateral acceleration
    (= its peak deceleration) is within maxAcceleration and maxDeceleration, pi sqrt(d / (2 a)),
    and whose peak lateral speed pi d / (2 T) is within maxSpeed: the longer of the two."""
    d = abs(change)
    acc, dec, speed = b.limits or (None, None, None)
    rates = [x for x in (acc, dec) if x is not None and x > 0]
    duration = math.pi * math.sqrt(d / (2.0 * min(rates))) if rates else 0.0
    if speed is not None and speed > 0:
        duration = max(duration, math.pi * d / (2.0 * speed))
    return duration


def next_lateral_speed(error: float, v_lat: float, dt: float, b: LateralDistanceAction) -> float:
    """The lateral speed (m/s, +t) for the coming step of ``dt`` s of an actor ``error`` m short
    of its goal moving at ``v_lat``: towards the goal as fast as maxSpeed allows and no faster
    than maxDeceleration can stop it there (sqrt(2 d e)), no further than the goal in the step;
    the change of speed within maxAcceleration (speeding up) or maxDeceleration (slowing
    down). A limit not given is unbounded."""
    acc, dec, speed = b.limits or (None, None, None)
    inf = math.inf
    acc = acc if acc is not None and acc > 0 else inf
    dec = dec if dec is not None and dec > 0 else inf
    speed = speed if speed is not None and speed > 0 else inf
    mag = min(speed, abs(error) / dt)
    if dec < inf:
        mag = min(mag, math.sqrt(2.0 * dec * abs(error)))
    want = math.copysign(mag, error)
    change = want - v_lat
    speeding_up = want * v_lat >= 0.0 and abs(want) > abs(v_lat)
    step = (acc if speeding_up else dec) * dt
    return v_lat + max(-step, min(step, change))
