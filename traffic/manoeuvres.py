"""Scripted manoeuvres: actors moved exactly along prescribed trajectories in SUMO.

A trajectory is given in road coordinates of one reference lane: ``s`` metres along the lane's
centre line, ``d`` metres to the left of it. Scripted vehicles are placed with libsumo's
``moveToXY`` every step (SUMO then reports the speed implied by the move), with SUMO's own
safety checks switched off, so they follow the script exactly (Annex G: other vehicles are
point masses moved as defined, not drivers).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import sumolib

#: t (s since script start) -> (s_centre m, d m, ds/dt m/s, dd/dt m/s)
Trajectory = Callable[[float], tuple[float, float, float, float]]


@dataclass(frozen=True)
class RoadFrame:
    """Road coordinates along a lane centre line (polyline) in network metres."""

    points: np.ndarray  # (K, 2)
    cum: np.ndarray  # (K,) arc length at each point
    edge: str
    lane_index: int

    @staticmethod
    def from_lane(net_file: str, lane_id: str) -> RoadFrame:
        """The frame of ``lane_id`` in the network ``net_file``."""
        lane = sumolib.net.readNet(str(net_file)).getLane(lane_id)
        pts = np.array([p[:2] for p in lane.getShape()], dtype=float)
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        return RoadFrame(
            pts, np.concatenate([[0.0], np.cumsum(seg)]), lane.getEdge().getID(), lane.getIndex()
        )

    @property
    def length(self) -> float:
        return float(self.cum[-1])

    def to_xy(self, s: float, d: float) -> tuple[float, float, float]:
        """(x, y, heading of the centre line) at arc length ``s``, offset ``d`` to the left."""
        k = int(np.clip(np.searchsorted(self.cum, s, side="right") - 1, 0, len(self.cum) - 2))
        p0, p1 = self.points[k], self.points[k + 1]
        seg = self.cum[k + 1] - self.cum[k]
        u = (p1 - p0) / seg
        p = p0 + u * (s - self.cum[k])
        left = np.array([-u[1], u[0]])
        x, y = p + left * d
        return float(x), float(y), math.atan2(u[1], u[0])


def heading_to_sumo_angle(heading: float) -> float:
    """Radians CCW from +x -> SUMO's compass degrees (clockwise from north)."""
    return (90.0 - math.degrees(heading)) % 360.0


@dataclass
class ScriptedVehicle:
    """A SUMO vehicle that follows ``trajectory`` (road coordinates of ``frame``) exactly."""

    vid: str
    frame: RoadFrame
    trajectory: Trajectory
    length: float

    def place(self, sumo, t: float) -> None:
        """Move the vehicle to where the trajectory puts its centre at script time ``t``."""
        s, d, vs, vd = self.trajectory(t)
        x, y, road_h = self.frame.to_xy(s, d)
        h = road_h + math.atan2(vd, vs) if abs(vs) + abs(vd) > 1e-9 else road_h
        fx, fy = x + 0.5 * self.length * math.cos(h), y + 0.5 * self.length * math.sin(h)
        sumo.vehicle.moveToXY(
            self.vid,
            self.frame.edge,
            self.frame.lane_index,
            fx,
            fy,
            angle=heading_to_sumo_angle(h),
            keepRoute=2,
        )
        sumo.vehicle.setSpeed(self.vid, math.hypot(vs, vd))


@dataclass
class ScriptedPerson:
    """A SUMO person moved along ``trajectory`` (centre, road coordinates of ``frame``)."""

    pid: str
    frame: RoadFrame
    trajectory: Trajectory

    def place(self, sumo, t: float) -> None:
        s, d, vs, vd = self.trajectory(t)
        x, y, road_h = self.frame.to_xy(s, d)
        h = road_h + math.atan2(vd, vs) if abs(vs) + abs(vd) > 1e-9 else road_h
        sumo.person.moveToXY(
            self.pid, self.frame.edge, x, y, angle=heading_to_sumo_angle(h), keepRoute=2
        )


def add_vehicle(
    sumo,
    vid: str,
    route_edges: list[str],
    vtype: str,
    lane: int,
    pos: float,
    speed: float,
    scripted: bool,
) -> None:
    """Insert a vehicle now; ``scripted`` switches off SUMO's speed and lane-change logic."""
    rid = f"route_{vid}"
    sumo.route.add(rid, route_edges)
    sumo.vehicle.add(
        vid,
        rid,
        typeID=vtype,
        departLane=str(lane),
        departPos=f"{pos:.3f}",
        departSpeed=f"{speed:.3f}",
    )
    sumo.vehicle.setSpeedMode(vid, 0)
    sumo.vehicle.setLaneChangeMode(vid, 0)
