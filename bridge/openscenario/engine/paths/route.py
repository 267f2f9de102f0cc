"""Routes along the roads: the legs between the waypoints (the shortest way by road length,
net.road.topology), the route's own coordinates (path s from the first waypoint, t to the left
of the direction of travel) and the route sampled at a lateral offset for an actor to follow.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.openscenario.engine.paths.sampled import SampledPath
from hiyari.bridge.openscenario.model.positions import Position
from hiyari.bridge.openscenario.model.trajectories import Route
from hiyari.errors import HiyariError
from hiyari.net.road.opendrive_lanes import OpenDriveMap
from hiyari.net.road.topology import Leg, RoadGraph

#: Sample spacing along a route, m.
ROUTE_STEP = 0.5


@dataclass(frozen=True, eq=False)
class RoutePath:
    """The legs of a route and where each starts in path s (m)."""

    legs: tuple[Leg, ...]
    starts: np.ndarray

    @property
    def length(self) -> float:
        """Metres from the first waypoint to the last."""
        return float(self.starts[-1] + self.legs[-1].length)

    def road_at(self, path_s: float) -> tuple[str, float, int]:
        """(road, road s, direction) at ``path_s`` m along the route (clamped to it)."""
        path_s = min(max(path_s, 0.0), self.length)
        k = int(
            np.clip(np.searchsorted(self.starts, path_s, side="right") - 1, 0, len(self.legs) - 1)
        )
        leg = self.legs[k]
        return leg.road, leg.s0 + leg.direction * (path_s - self.starts[k]), leg.direction

    def path_s(self, road: str, s: float) -> float | None:
        """Path s of road point (``road``, ``s``) when the route passes it (the first pass),
        else None."""
        for k, leg in enumerate(self.legs):
            lo, hi = sorted((leg.s0, leg.s1))
            if leg.road == road and lo - 1e-6 <= s <= hi + 1e-6:
                return float(self.starts[k] + (s - leg.s0) * leg.direction)
        return None

    def sampled(self, odr: OpenDriveMap, t: float) -> SampledPath:
        """The route ``t`` m left of its reference line (in the direction of travel), sampled
        every ROUTE_STEP m along each leg."""
        pts = []
        for k, leg in enumerate(self.legs):
            n = max(2, int(np.ceil(leg.length / ROUTE_STEP)) + 1)
            s = np.linspace(leg.s0, leg.s1, n)
            x, y, _, _ = odr.road_pose(leg.road, s, np.full(n, t * leg.direction))
            xy = np.column_stack([x, y])
            pts.append(xy if k == 0 else xy[1:])
        return SampledPath.through(np.vstack(pts))


def random_destination(
    graph: RoadGraph,
    road: str,
    s: float,
    direction: int,
    rng: np.random.Generator,
    length: float = 1000.0,
) -> tuple[str, float, int]:
    """(road, s, direction) about ``length`` m on from road point (``road``, ``s``) driven in
    ``direction``, turning at random where the roads branch (a dead end stops short)."""
    left = length - (graph.lengths[road] - s if direction > 0 else s)
    while left > 0:
        exits = graph.exits.get((road, direction), ())
        if not exits:
            return road, (graph.lengths[road] if direction > 0 else 0.0), direction
        road, direction = exits[int(rng.integers(len(exits)))]
        left -= graph.lengths[road]
    end = graph.lengths[road] + left if direction > 0 else -left
    return road, float(np.clip(end, 0.0, graph.lengths[road])), direction


class _RoadPose:
    """What a resolver gives for a waypoint: its road, lane and s."""

    road: str
    lane: int
    s: float


def route_path(
    route: Route,
    odr: OpenDriveMap,
    graph: RoadGraph,
    resolve: Callable[[Position], _RoadPose],
    forward: Callable[[str, int], float],
) -> RoutePath:
    """The legs through ``route``'s waypoints (each driven in its lane's direction)."""
    poses = [resolve(w) for w in route.waypoints]
    if route.closed:
        poses.append(poses[0])
    legs: list[Leg] = []
    for a, b in zip(poses[:-1], poses[1:], strict=True):
        if not a.road or not b.road:
            raise HiyariError(f"route {route.name!r}: a waypoint is off every road")
        part = graph.route(
            (a.road, a.s, int(forward(a.road, a.lane))), (b.road, b.s, int(forward(b.road, b.lane)))
        )
        if legs and legs[-1].road == part[0].road and legs[-1].direction == part[0].direction:
            last = legs.pop()
            part[0] = Leg(last.road, last.direction, last.s0, part[0].s1)
        legs += part
    legs = [leg for leg in legs if leg.length > 0] or legs[:1]
    starts = np.concatenate([[0.0], np.cumsum([leg.length for leg in legs[:-1]])])
    return RoutePath(tuple(legs), starts)
