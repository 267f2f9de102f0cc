"""Sensor mounting and frames: where a sensor sits on the ego and how that maps to the world.

Ego frame: x forward, y left, z up, origin at the centre of the ego's ground rectangle (the
WorldState ``xyz``). Sensor frame: x along the boresight, y left, z up. Angles of a mount in
degrees: yaw positive to the left, pitch positive nose-down, roll positive right side down
(right-handed rotations about z, y and x, applied in that order).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from hiyari.errors import HiyariError
from hiyari.traffic.world_state import WorldState


class PoseLike(Protocol):
    """Anything with an ego pose: network metres, heading rad CCW from +x, speed m/s."""

    x: float
    y: float
    z: float
    heading: float
    speed: float


@dataclass(frozen=True)
class VehiclePose:
    """An actor's pose read from one WorldState row (satisfies PoseLike)."""

    x: float
    y: float
    z: float
    heading: float
    speed: float

    @staticmethod
    def from_world(world: WorldState, actor_id: str) -> VehiclePose:
        """Pose of ``actor_id`` in ``world``; HiyariError when it is not there."""
        try:
            row = world.index(actor_id)
        except KeyError:
            raise HiyariError(
                f"ego {actor_id!r} is not in the WorldState at t={world.time} s"
            ) from None
        return VehiclePose(
            float(world.xyz[row, 0]),
            float(world.xyz[row, 1]),
            float(world.xyz[row, 2]),
            float(world.heading[row]),
            float(world.speed[row]),
        )


def rotation(yaw: float, pitch: float, roll: float) -> np.ndarray:
    """(3, 3) rotation Rz(yaw) Ry(pitch) Rx(roll), radians."""
    cy, sy = np.cos(yaw), np.sin(yaw)
    cp, sp = np.cos(pitch), np.sin(pitch)
    cr, sr = np.cos(roll), np.sin(roll)
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return rz @ ry @ rx


@dataclass(frozen=True)
class Mount:
    """A sensor's pose on the ego, in the ego frame (metres, degrees)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 1.5
    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    roll_deg: float = 0.0

    def sensor_to_ego(self) -> np.ndarray:
        """(4, 4) transform from the sensor frame to the ego frame."""
        m = np.eye(4)
        m[:3, :3] = rotation(
            np.radians(self.yaw_deg), np.radians(self.pitch_deg), np.radians(self.roll_deg)
        )
        m[:3, 3] = [self.x, self.y, self.z]
        return m


def ego_to_world(ego: PoseLike) -> np.ndarray:
    """(4, 4) transform from the ego frame to network coordinates (flat: no pitch or roll)."""
    c, s = np.cos(ego.heading), np.sin(ego.heading)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:3, 3] = [ego.x, ego.y, ego.z]
    return m


def sensor_to_world(mount: Mount, ego: PoseLike) -> np.ndarray:
    """(4, 4) transform from the sensor frame to network coordinates."""
    return ego_to_world(ego) @ mount.sensor_to_ego()


def ego_velocity(ego: PoseLike) -> np.ndarray:
    """(3,) ego velocity in the network frame, m/s (along the heading)."""
    return ego.speed * np.array([np.cos(ego.heading), np.sin(ego.heading), 0.0])
