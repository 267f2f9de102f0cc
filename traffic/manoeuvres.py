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

from hiyari.net.road.lane_frame import RoadFrame
from hiyari.traffic.commands import Commands

#: t (s since script start) -> (s_centre m, d m, ds/dt m/s, dd/dt m/s)
Trajectory = Callable[[float], tuple[float, float, float, float]]


@dataclass
class ScriptedVehicle:
    """A SUMO vehicle that follows ``trajectory`` (road coordinates of ``frame``) exactly."""

    vid: str
    frame: RoadFrame
    trajectory: Trajectory
    length: float

    def place(self, sim: Commands, t: float) -> None:
        """Move the vehicle to where the trajectory puts its centre at script time ``t``."""
        s, d, vs, vd = self.trajectory(t)
        x, y, road_h = self.frame.to_xy(s, d)
        h = road_h + math.atan2(vd, vs) if abs(vs) + abs(vd) > 1e-9 else road_h
        sim.move_vehicle(
            self.vid,
            x,
            y,
            h,
            self.length,
            speed=math.hypot(vs, vd),
            edge=self.frame.edge,
            lane=self.frame.lane_index,
        )


@dataclass
class ScriptedPerson:
    """A SUMO person moved along ``trajectory`` (centre, road coordinates of ``frame``)."""

    pid: str
    frame: RoadFrame
    trajectory: Trajectory

    def place(self, sim: Commands, t: float) -> None:
        """Move the person to where the trajectory puts it at script time ``t``."""
        s, d, vs, vd = self.trajectory(t)
        x, y, road_h = self.frame.to_xy(s, d)
        h = road_h + math.atan2(vd, vs) if abs(vs) + abs(vd) > 1e-9 else road_h
        sim.move_person(self.pid, x, y, h, edge=self.frame.edge)
