"""Where a catalogue scenario happens on its generated road: the ego's lane and start, the
lane of each surrounding-vehicle position, and the lanes motions lead to.

Motorway roads (hiyari.net.road.xodr_writer): road "main" along +x, lane -1 leftmost, lane
-n rightmost, lane -(n+1) the merge (acceleration) or exit lane. Right-hand traffic (the
OpenDRIVE default; JAMA's Japanese roads drive on the left: mirror the results).
"""

from __future__ import annotations

from dataclasses import dataclass

from hiyari.bridge.studies.catalogue.space.taxonomy import EgoMotion, Geometry, Motion, Position

#: Ego start station (m) per geometry: the merge events end before the acceleration lane
#: does (700 m); on the branch everyone starts beside the exit lane (from 700 m).
START_STATION = {Geometry.MAIN: 200.0, Geometry.MERGE: 150.0, Geometry.BRANCH: 780.0}
LANE_WIDTH = 3.5
#: Side of a position: +1 left, -1 right, 0 the ego's lane.
SIDE = {
    Position.FRONT: 0,
    Position.REAR: 0,
    Position.PLUS_ONE: 0,
    Position.LEFT_FRONT: 1,
    Position.LEFT_REAR: 1,
    Position.RIGHT_FRONT: -1,
    Position.RIGHT_REAR: -1,
}
BEHIND = {Position.REAR, Position.LEFT_REAR, Position.RIGHT_REAR}


@dataclass(frozen=True)
class MotorwayLayout:
    """One motorway geometry with ``lanes`` through lanes and the ego's motion on it."""

    geometry: Geometry
    ego_motion: EgoMotion
    lanes: int
    lane_width: float = LANE_WIDTH

    @property
    def extra_lane(self) -> int | None:
        """The merge / exit lane's id (None on the main line)."""
        return None if self.geometry == Geometry.MAIN else -(self.lanes + 1)

    def exists(self, lane: int) -> bool:
        """Whether OpenDRIVE lane ``lane`` exists where the scenario plays."""
        return -self.lanes <= lane <= -1 or lane == self.extra_lane

    @property
    def ego_lane(self) -> int:
        """The ego's start lane: main line: lane -2 (right of 2, middle of 3); merge lane
        change: the acceleration lane; otherwise the rightmost through lane (beside the merge
        / exit lane)."""
        if self.geometry == Geometry.MAIN:
            return -2
        if self.geometry == Geometry.MERGE and self.ego_motion == EgoMotion.LANE_CHANGE:
            return -(self.lanes + 1)
        return -self.lanes

    @property
    def ego_target(self) -> int:
        """The ego's lane after its lane change (its own lane when it keeps it): main line
        and merge: one lane left; branch: into the exit lane."""
        if self.ego_motion != EgoMotion.LANE_CHANGE:
            return self.ego_lane
        return self.ego_lane - 1 if self.geometry == Geometry.BRANCH else self.ego_lane + 1

    @property
    def start(self) -> float:
        return START_STATION[self.geometry]

    def lane_of(self, position: Position) -> int | None:
        """OpenDRIVE lane of a surrounding vehicle at ``position`` (None: no such lane)."""
        lane = self.ego_lane + SIDE[position]
        return lane if self.exists(lane) else None

    def target_lane(self, position: Position, motion: Motion) -> tuple[int | None, str]:
        """The lane a lateral ``motion`` from ``position`` ends in, or None with the reason
        it is undefined there."""
        lane = self.lane_of(position)
        if lane is None:
            return None, "no such lane"
        side = SIDE[position]
        if motion == Motion.CUT_IN:
            if side == 0:
                return None, "already in the ego's lane: no cut-in"
            return self.ego_lane, ""
        if motion == Motion.CUT_OUT:
            # away from the ego's lane; from the ego's lane: left when it exists, else right
            order = [side] if side else [1, -1]
            for d in order:
                if self.exists(lane + d):
                    return lane + d, ""
            return None, "no lane to cut out into"
        if motion == Motion.SWERVE:
            return lane, ""
        return lane, ""

    def centre_t(self, lane: int) -> float:
        """Lateral position (m, +left) of a lane's centre line."""
        return -(abs(lane) - 0.5) * self.lane_width
