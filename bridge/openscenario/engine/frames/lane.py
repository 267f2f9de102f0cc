"""Distances, headways and times to collision in lane coordinates (coordinateSystem="lane"):
longitudinally along the centre line of the triggering entity's lane, laterally in lanes.

Between two reference points (or, with freespace, the boxes' ends) on the triggering entity's
road: the longitudinal distance is the length of the triggering entity's lane's centre line
between their road s (on a curve longer or shorter than the s difference by the lane's offset
times the curvature); the lateral distance is the number of lanes between their lanes (lane 0
not counted, whatever their offsets within the lanes); euclidean combines the longitudinal
distance with the road t difference (m). On different roads linked by road links or a
junction the longitudinal distance is the way along their reference lines (frames.links; the
lane's offset is not counted there) and the lateral one the difference of the lane ids as on
one road; on unlinked roads, or off the roads, nothing is measured (NaN: no rule holds).
Speeds are taken along the lane (the entities' own speeds, signed by their directions of
travel). Measured in Python each step the condition is evaluated: OpenSCENARIO files rarely
use this frame.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from hiyari.bridge.openscenario.engine.frames.links import road_ahead
from hiyari.bridge.openscenario.engine.positions import Pose
from hiyari.bridge.openscenario.model.conditions import (
    CoordinateSystem,
    DistanceCondition,
    DistanceType,
    RelativeDistanceCondition,
    TimeHeadwayCondition,
    TimeToCollisionCondition,
)

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine

#: Spacing (m) of the points along a lane centre whose polyline measures its length.
STEP = 0.5

LaneCondition = (
    RelativeDistanceCondition | DistanceCondition | TimeHeadwayCondition | TimeToCollisionCondition
)


def relative_lane(own: int, other: int, direction: float) -> int:
    """Lanes from ``own`` to ``other`` (OpenDRIVE ids, 0 skipped), positive to the left of a
    travel ``direction`` of +1 (increasing s) or -1."""
    steps = other - own
    if own < 0 < other:
        steps -= 1
    elif other < 0 < own:
        steps += 1
    return int(steps * direction)


def lane_length(engine: ScenarioEngine, road: str, lane: int, s0: float, s1: float) -> float:
    """Length (m) of lane ``lane``'s centre line of ``road`` from road ``s0`` to ``s1``
    (signed: negative when ``s1 < s0``), as a polyline of points about STEP m apart."""
    if s1 == s0:
        return 0.0
    n = max(2, math.ceil(abs(s1 - s0) / STEP) + 1)
    s = np.linspace(s0, s1, n)
    odr = engine.roads.odr
    t, _ = odr.road(road).lane_centre_t(lane, s)
    x, y, _, _ = odr.road_pose(road, s, t)
    return math.copysign(float(np.hypot(np.diff(x), np.diff(y)).sum()), s1 - s0)


def box_extent(engine: ScenarioEngine, name: str | None) -> tuple[float, float, float]:
    """(front, rear, half width) of entity ``name``'s box from its reference point, m (along
    and across its x; 0 for a point, ``name`` None)."""
    if name is None:
        return 0.0, 0.0, 0.0
    e = engine.actors[name].entity
    return e.centre[0] + 0.5 * e.length, 0.5 * e.length - e.centre[0], 0.5 * e.width


def target(
    engine: ScenarioEngine, b: LaneCondition, pose_of: Callable[[str], Pose]
) -> tuple[Pose, str | None]:
    """The pose (by ``pose_of``) and name of what condition ``b`` measures to: its position
    (name None) or its entity."""
    if isinstance(b, DistanceCondition) or (
        isinstance(b, TimeToCollisionCondition) and b.entity is None
    ):
        return engine.resolver.resolve(b.position), None
    return pose_of(b.entity), b.entity


def time_measure(b: LaneCondition, dist: float, ahead: float, v: float, v_other: float) -> float:
    """Headway (s) or time to collision (s) of ``b`` over ``dist`` m, the other ``ahead``
    (signed, + ahead), at own speed ``v`` and the other's ``v_other`` along the frame (m/s)."""
    if isinstance(b, TimeHeadwayCondition):
        return dist / v if ahead > 0 and v > 1e-6 else math.inf
    closing = (v - v_other) if ahead >= 0 else (v_other - v)
    return dist / closing if closing > 1e-9 else math.inf


def _gap(
    engine: ScenarioEngine,
    name: str,
    me: Pose,
    other: Pose,
    other_name: str | None,
    freespace: bool,
    dtype: DistanceType,
) -> tuple[float, float]:
    """(distance by ``dtype``, longitudinal distance signed: + with ``other`` ahead) of
    ``other`` from entity ``name`` at ``me`` in lane coordinates; NaN off its road."""
    if not me.road or not other.road:
        return math.nan, math.nan
    direction = engine.travel_direction(name)
    if other.road == me.road:
        ahead = direction * lane_length(engine, me.road, me.lane, me.s, other.s)
    else:
        graph = engine.resolver.graph()
        ahead = road_ahead(graph, me.road, me.s, direction, other.road, other.s)
        if math.isnan(ahead):
            return math.nan, math.nan
    lon = abs(ahead)
    if freespace:
        front, rear, _ = box_extent(engine, name)
        o_front, o_rear, _ = box_extent(engine, other_name)
        lon = max(0.0, lon - (front + o_rear if ahead >= 0 else rear + o_front))
    if dtype == DistanceType.LONGITUDINAL:
        return lon, ahead
    if dtype == DistanceType.LATERAL:
        return float(abs(relative_lane(me.lane, other.lane, direction))), ahead
    return math.hypot(lon, other.t - me.t), ahead


def lane_measure(engine: ScenarioEngine, name: str, b: LaneCondition) -> float:
    """The distance (m; lanes laterally), headway (s) or time to collision (s) of ``b`` for
    triggering entity ``name`` in lane coordinates (NaN: not measurable now)."""
    me = engine.road_pose(name)
    other, other_name = target(engine, b, engine.road_pose)
    dtype = getattr(b, "distance_type", DistanceType.EUCLIDEAN)
    dist, ahead = _gap(engine, name, me, other, other_name, b.freespace, dtype)
    if isinstance(b, RelativeDistanceCondition | DistanceCondition):
        return dist
    # along the lane: the other's speed counts with the sign of its direction against mine
    v_other = 0.0
    if other_name is not None:
        same = engine.travel_direction(other_name) == engine.travel_direction(name)
        v_other = engine.speed_of(other_name) * (1.0 if same else -1.0)
    return time_measure(b, dist, ahead, engine.speed_of(name), v_other)


def in_lane_frame(body: object) -> bool:
    """Whether condition ``body`` measures in lane coordinates (here, not in the kernel)."""
    return isinstance(body, LaneCondition) and body.coordinate_system == CoordinateSystem.LANE
