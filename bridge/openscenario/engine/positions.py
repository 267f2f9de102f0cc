"""Resolve model positions to poses on the map, given where the entities are now."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from hiyari.bridge.openscenario.engine.motion import curvature
from hiyari.bridge.openscenario.engine.paths.route import RoutePath, route_path
from hiyari.bridge.openscenario.engine.paths.sampled import SampledPath
from hiyari.bridge.openscenario.engine.paths.trajectory import sample_trajectory
from hiyari.bridge.openscenario.model.positions import (
    GeoPosition,
    LanePosition,
    Orientation,
    Position,
    RelativeLanePosition,
    RelativeObjectPosition,
    RelativeRoadPosition,
    RelativeWorldPosition,
    RoadPosition,
    RoutePosition,
    TrajectoryPosition,
    WorldPosition,
)
from hiyari.bridge.openscenario.model.trajectories import Route, Trajectory
from hiyari.errors import HiyariError
from hiyari.net.road.geo import GeoReference
from hiyari.net.road.opendrive_lanes import OpenDriveMap
from hiyari.net.road.topology import RoadGraph


@dataclass(frozen=True)
class Pose:
    """A reference-point pose: network x, y, z (m), heading h (rad), and its road
    coordinates (road '' when off every road)."""

    x: float
    y: float
    z: float
    h: float
    road: str
    lane: int
    s: float
    t: float


def lane_shift(lane: int, n: int) -> int:
    """Lane id ``n`` lanes further in +t (n > 0) or -t, skipping the centre lane 0."""
    if n == 0:
        return lane
    step = 1 if n > 0 else -1
    for _ in range(abs(n)):
        lane += step
        if lane == 0:
            lane += step
    return lane


class PoseResolver:
    """Turns positions into poses; ``pose_of(name)`` gives an entity's current pose."""

    def __init__(self, odr: OpenDriveMap, pose_of: Callable[[str], Pose]) -> None:
        self.odr = odr
        self.pose_of = pose_of
        self._graph: RoadGraph | None = None
        self._geo: GeoReference | None = None
        self._routes: dict[Route, RoutePath] = {}
        self._lines: dict[Route, SampledPath] = {}
        self._paths: dict[Trajectory, SampledPath] = {}

    # ------------------------------------------------------------------ paths
    def graph(self) -> RoadGraph:
        """How this map's roads connect (read once)."""
        if self._graph is None:
            self._graph = RoadGraph.from_file(self.odr.path)
        return self._graph

    def route(self, route: Route) -> RoutePath:
        """The legs of ``route`` on this map (found once per route)."""
        found = self._routes.get(route)
        if found is None:
            found = route_path(
                route, self.odr, self.graph(), self.resolve,
                lambda r, ln: 1.0 if self.odr.road(r).drives_forward(ln) else -1.0,
            )  # fmt: skip
            self._routes[route] = found
        return found

    def route_line(self, route: Route) -> SampledPath:
        """``route``'s reference line (t = 0), sampled (kept per route)."""
        found = self._lines.get(route)
        if found is None:
            found = self._lines[route] = self.route(route).sampled(self.odr, 0.0)
        return found

    def trajectory(self, traj: Trajectory, start: Pose | None = None) -> SampledPath:
        """The path of ``traj`` (``start``: the following entity's pose, for a trajectory
        that starts where the entity is); kept when it depends on no entity."""
        found = self._paths.get(traj)
        if found is not None:
            return found
        path = sample_trajectory(traj, self.resolve, start)
        if _fixed(traj):
            self._paths[traj] = path
        return path

    def at_lane(self, road: str, lane: int, s: float, offset: float, h_rel: float = 0.0) -> Pose:
        """Pose at a lane position, heading along the lane's driving direction + ``h_rel``."""
        rd = self.odr.road(road)
        if not -1e-6 <= s <= rd.length + 1e-6:
            raise HiyariError(
                f"{self.odr.path}: s = {s:g} m is off road {road} (length {rd.length:g} m)"
            )
        t = float(rd.lane_centre_t(lane, np.array([s]))[0][0]) + offset
        return self.at_road(road, s, t, lane, h_rel)

    def at_road(
        self, road: str, s: float, t: float, lane: int | None = None, h_rel: float = 0.0
    ) -> Pose:
        """Pose at road ``s``, ``t``; lane located from t when not given."""
        x, y, z, h = self.odr.road_pose(road, np.array([s]), np.array([t]))
        rd = self.odr.road(road)
        if lane is None:
            lane = self.odr.locate(x, y, road)[0].lane
        # the centre lane (0) has no driving direction: along s
        heading = float(h[0]) + (0.0 if lane == 0 or rd.drives_forward(lane) else math.pi)
        return Pose(float(x[0]), float(y[0]), float(z[0]), _wrap(heading + h_rel), road, lane, s, t)

    def at_xy(self, x: float, y: float, h: float, z: float = 0.0) -> Pose:
        """Pose at a world point, with its road coordinates when near a road."""
        rc = self.odr.locate(np.array([x]), np.array([y]))[0]
        return Pose(x, y, z, h, rc.road, rc.lane, rc.s, rc.t)

    def resolve(self, pos: Position) -> Pose:
        """The pose ``pos`` stands for now."""
        if isinstance(pos, WorldPosition):
            return self.at_xy(pos.x, pos.y, pos.h, pos.z)
        if isinstance(pos, LanePosition):
            return self._orient(
                self.at_lane(pos.road, pos.lane, pos.s, pos.offset), pos.orientation
            )
        if isinstance(pos, RoadPosition):
            return self._orient(self.at_road(pos.road, pos.s, pos.t), pos.orientation)
        if isinstance(pos, TrajectoryPosition):
            path = self.trajectory(pos.trajectory)
            x, y, h = path.pose(pos.s, pos.t)
            return self._orient(self.at_xy(x, y, h), pos.orientation)
        if isinstance(pos, RoutePosition):
            return self._route_position(pos)
        if isinstance(pos, GeoPosition):
            if self._geo is None:
                self._geo = GeoReference.from_file(self.odr.path)
            x, y = self._geo.to_map(pos.latitude, pos.longitude)
            p = self.at_xy(x, y, 0.0, pos.altitude)
            # the heading of a geographic position is its orientation's, else the road's
            if p.road and (pos.orientation is None or pos.orientation.relative):
                p = replace(p, h=self.at_road(p.road, p.s, p.t, p.lane).h)
            return self._orient(p, pos.orientation)
        ref = self.pose_of(pos.entity)
        if isinstance(pos, RelativeLanePosition):
            return self._relative_lane(pos, ref)
        if isinstance(pos, RelativeRoadPosition):
            p = self.at_road(ref.road, ref.s + pos.ds, ref.t + pos.dt)
            return self._orient(p, pos.orientation)
        if isinstance(pos, RelativeObjectPosition):
            c, s = math.cos(ref.h), math.sin(ref.h)
            p = self.at_xy(ref.x + pos.dx * c - pos.dy * s, ref.y + pos.dx * s + pos.dy * c, ref.h)
            return self._orient(p, pos.orientation, ref.h)
        if isinstance(pos, RelativeWorldPosition):
            p = self.at_xy(ref.x + pos.dx, ref.y + pos.dy, ref.h)
            return self._orient(p, pos.orientation, ref.h)
        raise HiyariError(f"position {type(pos).__name__} is not supported")

    def _route_position(self, pos: RoutePosition) -> Pose:
        if pos.entity is not None:
            return self._orient(self.pose_of(pos.entity), pos.orientation)
        road, s, direction = self.route(pos.route).road_at(pos.path_s)
        if pos.lane is not None:  # lane ids and offsets count in the route's direction
            p = self.at_lane(road, pos.lane * direction, s, pos.lane_offset * direction)
        else:
            x, y, z, h = self.odr.road_pose(road, np.array([s]), np.array([pos.t * direction]))
            lane = self.odr.locate(x, y, road)[0].lane
            h_travel = float(h[0]) + (0.0 if direction > 0 else math.pi)
            p = Pose(float(x[0]), float(y[0]), float(z[0]), _wrap(h_travel), road, lane, s,
                     pos.t * direction)  # fmt: skip
        return self._orient(p, pos.orientation)

    def _relative_lane(self, pos: RelativeLanePosition, ref: Pose) -> Pose:
        if not ref.road:
            raise HiyariError(f"entity {pos.entity!r} is not on a road for a RelativeLanePosition")
        lane = lane_shift(ref.lane, pos.d_lane)
        ds = pos.ds
        if pos.ds_lane:  # along the lane's centre line: scale by the curvature there
            t_c = float(self.odr.road(ref.road).lane_centre_t(lane, np.array([ref.s]))[0][0])
            ds /= max(1e-3, 1.0 - float(curvature(self.odr, ref.road, np.array([ref.s]))[0]) * t_c)
        p = self.at_lane(ref.road, lane, ref.s + ds, pos.offset)
        return self._orient(p, pos.orientation)

    @staticmethod
    def _orient(p: Pose, o: Orientation | None, base: float | None = None) -> Pose:
        if o is None:
            return p
        h = (p.h if base is None else base) + o.h if o.relative else o.h
        return Pose(p.x, p.y, p.z, _wrap(h), p.road, p.lane, p.s, p.t)


def _fixed(traj: Trajectory) -> bool:
    """Whether ``traj``'s positions stay where they are (none is relative to an entity, and
    it does not start where its entity is)."""
    shape = traj.shape
    positions = [getattr(shape, "position", None)]
    positions += [v.position for v in getattr(shape, "vertices", ())]
    positions += [c.position for c in getattr(shape, "control_points", ())]
    segs = getattr(shape, "segments", ())
    if segs and segs[0].position_start is None:
        return False
    positions += [g.position_start for g in segs]
    fixed = (WorldPosition, LanePosition, RoadPosition)
    return all(p is None or isinstance(p, fixed) for p in positions)


def _wrap(h: float) -> float:
    return math.remainder(h, 2 * math.pi)
