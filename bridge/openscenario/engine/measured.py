"""Conditions measured in Python each step their trigger is evaluated: relative clearance,
angles, time of day, distances / headways / TTCs in lane and trajectory coordinates
(frames.lane, frames.trajectory).

RelativeClearanceCondition: whether the space around a triggering entity is free of other
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

import math
from datetime import datetime, timedelta
from typing import TYPE_CHECKING

from hiyari.bridge.openscenario.engine.frames.lane import (
    LaneCondition,
    lane_measure,
    relative_lane,
)
from hiyari.bridge.openscenario.engine.frames.trajectory import trajectory_measure
from hiyari.bridge.openscenario.engine.kernels.measures import holds
from hiyari.bridge.openscenario.model.conditions import (
    AngleCondition,
    CollisionCondition,
    CoordinateSystem,
    DistanceCondition,
    EntityCondition,
    RelativeAngleCondition,
    RelativeClearanceCondition,
    RelativeDistanceCondition,
    Rule,
    TimeHeadwayCondition,
    TimeOfDayCondition,
    TimeToCollisionCondition,
)
from hiyari.errors import HiyariError

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine


def entity_holds(engine: ScenarioEngine, ec: EntityCondition) -> bool:
    """Whether ``ec`` (relative clearance, angle, relative angle) holds now for "any" / "all"
    of its triggering entities (an absent one does not hold)."""
    measure = {
        RelativeClearanceCondition: _clear,
        AngleCondition: _angle,
        RelativeAngleCondition: _relative_angle,
        CollisionCondition: _collides_with_type,
        RelativeDistanceCondition: _in_lanes,
        DistanceCondition: _in_lanes,
        TimeHeadwayCondition: _in_lanes,
        TimeToCollisionCondition: _in_lanes,
    }[type(ec.body)]
    results = [_present(engine, n) and measure(engine, n, ec.body) for n in ec.triggering]
    return any(results) if ec.rule != "all" else all(results)


def _in_lanes(engine: ScenarioEngine, name: str, b: LaneCondition) -> bool:
    """A distance, headway or TTC condition in lane or trajectory coordinates (see
    frames.lane, frames.trajectory)."""
    if b.coordinate_system == CoordinateSystem.TRAJECTORY:
        m = trajectory_measure(engine, name, b)
    else:
        m = lane_measure(engine, name, b)
    return bool(holds(m, b.value, list(Rule).index(b.rule)))


_KIND_TYPE = {"vehicle": "vehicle", "pedestrian": "pedestrian", "misc": "miscellaneous"}


def _collides_with_type(engine: ScenarioEngine, name: str, b: CollisionCondition) -> bool:
    """In contact (overlapping outlines) with an object of type ``b.by_type``: a scenario
    entity of that kind, or SUMO traffic (pedestrian or vehicle)."""
    world = engine._world
    for col in engine._sim.collisions:
        if col.depth <= 0.0 or name not in (col.a, col.b):
            continue
        other = col.b if col.a == name else col.a
        if other in engine.actors:
            kind = _KIND_TYPE[engine.actors[other].entity.kind.value]
        else:
            row = world.index(other) if world is not None and other in world.ids else -1
            kind = "pedestrian" if row >= 0 and world.is_pedestrian[row] else "vehicle"
        if kind == b.by_type:
            return True
    return False


def _angle_of(engine: ScenarioEngine, name: str, kind: str) -> float:
    """An entity's heading (rad, from +x); pitch and roll: 0 (level actors)."""
    return engine.road_pose(name).h if kind == "heading" else 0.0


def _angle(engine: ScenarioEngine, name: str, b: AngleCondition) -> bool:
    a = _angle_of(engine, name, b.angle_type)
    # road and lane frames measure against the road's direction; entity and world: absolute
    if b.angle_type == "heading" and b.coordinate_system in (
        CoordinateSystem.ROAD,
        CoordinateSystem.LANE,
    ):
        p = engine.road_pose(name)
        if not p.road:
            return False
        h_ref = float(engine.roads.odr.road(p.road).reference([p.s])[2][0])
        if engine.travel_direction(name) < 0:
            h_ref += math.pi
        a -= h_ref
    return abs(math.remainder(a - b.angle, 2 * math.pi)) <= b.tolerance


def _relative_angle(engine: ScenarioEngine, name: str, b: RelativeAngleCondition) -> bool:
    if not _present(engine, b.entity):
        return False
    a = _angle_of(engine, name, b.angle_type) - _angle_of(engine, b.entity, b.angle_type)
    return abs(math.remainder(a - b.angle, 2 * math.pi)) <= b.tolerance


def time_of_day_holds(engine: ScenarioEngine, b: TimeOfDayCondition, where: str) -> bool:
    """Whether the time of day (the environment's, on by the scenario time when animated)
    compared by the rule with ``b.date_time`` holds; HiyariError when no environment gives a
    time of day."""
    env = engine.environment
    if env is None or env.time_of_day is None:
        raise HiyariError(
            f"{where}: TimeOfDayCondition, but no EnvironmentAction gave a time of day"
        )
    now = _parse(env.time_of_day, where)
    if env.animated:
        now += timedelta(seconds=engine.now)
    want = _parse(b.date_time, where)
    diff = (now - want).total_seconds()
    return bool(holds(diff, 0.0, list(Rule).index(b.rule)))


def _parse(text: str, where: str) -> datetime:
    try:
        t = datetime.fromisoformat(text)
    except ValueError:
        raise HiyariError(f"{where}: {text!r} is not an ISO 8601 date and time") from None
    return t.replace(tzinfo=None) if t.tzinfo is None else t


def _present(engine: ScenarioEngine, name: str) -> bool:
    if engine.storyboard_drives(name):
        return engine.actors[name].inserted
    return name in engine._rows


def _clear(engine: ScenarioEngine, name: str, b: RelativeClearanceCondition) -> bool:
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
