"""RelativeClearanceCondition: whether the space around a triggering entity is free of other
entities, in road coordinates.

For a triggering entity on a road, another entity counts when it is on the same road, in a
lane of the ranges (relative lanes counted from the triggering entity's lane towards its left
in its direction of travel, lane 0 skipped; every lane when no range is given; lanes of the
opposite direction only when ``opposite``), and from ``backward`` m behind to ``forward`` m
ahead along the road (between reference points, or between the boxes' ends with
``freespace``). The condition holds for "any" / "all" of the triggering entities as its rule
says; an absent or off-road triggering entity does not hold.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from hiyari.bridge.openscenario.model.conditions import EntityCondition, RelativeClearanceCondition

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine


def relative_lane(own: int, other: int, direction: float) -> int:
    """Lanes from ``own`` to ``other`` (OpenDRIVE ids, 0 skipped), positive to the left of a
    travel ``direction`` of +1 (increasing s) or -1."""
    steps = other - own
    if own < 0 < other:
        steps -= 1
    elif other < 0 < own:
        steps += 1
    return int(steps * direction)


def clearance_holds(engine: ScenarioEngine, ec: EntityCondition) -> bool:
    """Whether ``ec`` (a RelativeClearanceCondition) holds now."""
    results = [_clear(engine, name, ec.body) for name in ec.triggering]
    return any(results) if ec.rule != "all" else all(results)


def _present(engine: ScenarioEngine, name: str) -> bool:
    if engine.storyboard_drives(name):
        return engine.actors[name].inserted
    return name in engine._rows


def _clear(engine: ScenarioEngine, name: str, b: RelativeClearanceCondition) -> bool:
    if not _present(engine, name):
        return False
    me = engine.road_pose(name)
    if not me.road:
        return False
    direction = engine.travel_direction(name)
    ent = engine.actors[name].entity
    others = b.entities or tuple(n for n in engine.names if n != name)
    for other in others:
        if other == name or not _present(engine, other):
            continue
        p = engine.road_pose(other)
        if p.road != me.road:
            continue
        if not b.opposite and engine.travel_direction(other) != direction:
            continue
        rel = relative_lane(me.lane, p.lane, direction)
        if b.lanes and not any(lo <= rel <= hi for lo, hi in b.lanes):
            continue
        ahead = (p.s - me.s) * direction
        if b.freespace:  # from the boxes' ends: my front to its rear, my rear to its front
            o = engine.actors[other].entity
            if ahead >= 0:
                ahead = max(
                    0.0, ahead - (ent.centre[0] + ent.length / 2) - (o.length / 2 - o.centre[0])
                )
            else:
                ahead = min(
                    0.0, ahead + (ent.length / 2 - ent.centre[0]) + (o.centre[0] + o.length / 2)
                )
        if -b.backward <= ahead <= b.forward:
            return False
    return True
