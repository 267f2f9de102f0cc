"""LateralDistanceAction: where across the road the actor is to be, relative to its reference
entity (road t, metres, positive to the left of the reference line)."""

from __future__ import annotations

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
