"""Positions: world, OpenDRIVE road / lane, and relative to other entities.

Metres and radians. Road coordinates: ``s`` along the road's reference line, ``t`` to its left;
lane ``offset`` from the lane's centre line in the road's t direction; lane ids as in OpenDRIVE
(negative: right of the reference line). Headings counter-clockwise from +x.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.model.trajectories import Route, Trajectory

__all__ = [
    "GeoPosition",
    "LanePosition",
    "Orientation",
    "Position",
    "RelativeLanePosition",
    "RelativeObjectPosition",
    "RelativeRoadPosition",
    "RelativeWorldPosition",
    "RoadPosition",
    "RoutePosition",
    "TrajectoryPosition",
    "WorldPosition",
]


@dataclass(frozen=True)
class Orientation:
    """Heading ``h`` (rad); ``relative`` True: added to the reference's heading (the road's
    driving direction for road / lane positions, the entity's for relative positions)."""

    h: float = 0.0
    relative: bool = True


@dataclass(frozen=True)
class WorldPosition:
    """Network x, y, z (m) and heading h (rad)."""

    x: float
    y: float
    z: float = 0.0
    h: float = 0.0


@dataclass(frozen=True)
class LanePosition:
    """OpenDRIVE road / lane / s with a lateral ``offset`` from the lane centre (m)."""

    road: str
    lane: int
    s: float
    offset: float = 0.0
    orientation: Orientation | None = None


@dataclass(frozen=True)
class RoadPosition:
    """OpenDRIVE road / s / t (m)."""

    road: str
    s: float
    t: float
    orientation: Orientation | None = None


@dataclass(frozen=True)
class RelativeLanePosition:
    """``d_lane`` lanes (lane-id arithmetic, skipping 0) and ``ds`` m along the road from an
    entity's lane position, ``offset`` m from the new lane's centre. ``ds_lane`` True: ds is
    measured along the lane's centre line instead of the reference line."""

    entity: str
    d_lane: int
    ds: float
    offset: float = 0.0
    ds_lane: bool = False
    orientation: Orientation | None = None


@dataclass(frozen=True)
class RelativeRoadPosition:
    """``ds``, ``dt`` (m) in road coordinates from an entity's road position."""

    entity: str
    ds: float
    dt: float
    orientation: Orientation | None = None


@dataclass(frozen=True)
class RelativeObjectPosition:
    """``dx`` forward, ``dy`` left (m) in the entity's own frame."""

    entity: str
    dx: float
    dy: float
    dz: float = 0.0
    orientation: Orientation | None = None


@dataclass(frozen=True)
class RelativeWorldPosition:
    """``dx``, ``dy`` (m) in network axes from the entity's reference point."""

    entity: str
    dx: float
    dy: float
    dz: float = 0.0
    orientation: Orientation | None = None


@dataclass(frozen=True)
class TrajectoryPosition:
    """``s`` m along ``trajectory`` and ``t`` m to its left; heading along the trajectory
    (+ ``orientation`` when relative)."""

    trajectory: Trajectory
    s: float
    t: float = 0.0
    orientation: Orientation | None = None


@dataclass(frozen=True)
class RoutePosition:
    """A position on ``route``: ``path_s`` m along it from its first waypoint, then ``t`` m to
    the left of its reference line, or, with ``lane``, ``lane_offset`` m (to the left) from
    that lane's centre on the road there; left, and the lane ids, count in the route's
    direction of travel (on a road driven against its s, lane -1 is its lane 1); with
    ``entity``: where that entity is."""

    route: Route
    path_s: float = 0.0
    t: float = 0.0
    lane: int | None = None
    lane_offset: float = 0.0
    entity: str | None = None
    orientation: Orientation | None = None


@dataclass(frozen=True)
class GeoPosition:
    """WGS84 ``latitude`` / ``longitude`` (rad) and ``altitude`` (m), mapped through the
    road's geoReference."""

    latitude: float
    longitude: float
    altitude: float = 0.0
    orientation: Orientation | None = None


Position = (
    WorldPosition
    | LanePosition
    | RoadPosition
    | RelativeLanePosition
    | RelativeRoadPosition
    | RelativeObjectPosition
    | RelativeWorldPosition
    | TrajectoryPosition
    | RoutePosition
    | GeoPosition
)
