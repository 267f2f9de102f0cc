"""Distances, headways and times to collision in trajectory coordinates
(coordinateSystem="trajectory"): s along the trajectory the triggering entity was given by its
latest FollowTrajectoryAction, t across it (positive to its left).

Both ends are projected on that trajectory (the nearest point of its sampled path): the
longitudinal distance is their s difference, the lateral one their t difference, euclidean
the two combined; with freespace less the boxes' extents (their length along s, their width
across). Speeds are taken along the trajectory (the component of each entity's velocity along
the trajectory's direction where it is). Before the entity has been given a trajectory
nothing is measured (NaN: no rule holds); a scenario whose triggering entity is given none at
all is refused when the engine is built (``check_trajectory_frames``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from hiyari.bridge.openscenario.engine.frames.lane import (
    LaneCondition,
    box_extent,
    target,
    time_measure,
)
from hiyari.bridge.openscenario.model.actions import FollowTrajectoryAction
from hiyari.bridge.openscenario.model.conditions import (
    CoordinateSystem,
    DistanceCondition,
    DistanceType,
    EntityCondition,
    RelativeDistanceCondition,
    Trigger,
)
from hiyari.bridge.openscenario.model.storyboard import Storyboard
from hiyari.errors import HiyariError

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine


def in_trajectory_frame(body: object) -> bool:
    """Whether condition ``body`` measures in trajectory coordinates."""
    return isinstance(body, LaneCondition) and body.coordinate_system == CoordinateSystem.TRAJECTORY


def _followers(board: Storyboard) -> set[str]:
    """The entities some FollowTrajectoryAction of the storyboard is for."""
    names = {i.entity for i in board.init if _follows(i.action.body)}
    for story in board.stories:
        for act in story.acts:
            for group in act.groups:
                for man in group.maneuvers:
                    for ev in man.events:
                        if any(_follows(a.body) for a in ev.actions):
                            names.update(group.actors)
    return names


def _follows(body: object) -> bool:
    return isinstance(body, FollowTrajectoryAction)


def check_trajectory_frames(board: Storyboard, triggers: list[Trigger]) -> None:
    """HiyariError (naming the condition's file and line) for a condition in trajectory
    coordinates whose triggering entity no FollowTrajectoryAction is for."""
    followers = _followers(board)
    for trig in triggers:
        for group in trig:
            for c in group:
                b = c.body
                if not (isinstance(b, EntityCondition) and in_trajectory_frame(b.body)):
                    continue
                for name in b.triggering:
                    if name not in followers:
                        raise HiyariError(
                            f"{c.source}: coordinateSystem trajectory, but {name!r} is given "
                            "no trajectory (no FollowTrajectoryAction for it)"
                        )


def trajectory_measure(engine: ScenarioEngine, name: str, b: LaneCondition) -> float:
    """The distance (m), headway (s) or time to collision (s) of ``b`` for triggering entity
    ``name`` in the coordinates of its trajectory (NaN: it has none yet)."""
    path = engine.trajectory_of.get(name)
    if path is None:
        return math.nan
    me = engine.pose_of(name)
    other, other_name = target(engine, b, engine.pose_of)
    s_a, t_a = path.project(me.x, me.y)
    s_b, t_b = path.project(other.x, other.y)
    ahead = s_b - s_a
    lon, lat = abs(ahead), abs(t_b - t_a)
    if b.freespace:
        front, rear, half = box_extent(engine, name)
        o_front, o_rear, o_half = box_extent(engine, other_name)
        lon = max(0.0, lon - (front + o_rear if ahead >= 0 else rear + o_front))
        lat = max(0.0, lat - half - o_half)
    dtype = getattr(b, "distance_type", DistanceType.EUCLIDEAN)
    dist = {DistanceType.LONGITUDINAL: lon, DistanceType.LATERAL: lat}.get(
        dtype, math.hypot(lon, lat)
    )
    if isinstance(b, RelativeDistanceCondition | DistanceCondition):
        return dist
    v = engine.speed_of(name) * math.cos(me.h - path.direction(s_a))
    v_other = 0.0
    if other_name is not None:
        v_other = engine.speed_of(other_name) * math.cos(other.h - path.direction(s_b))
    return time_measure(b, dist, ahead, v, v_other)
