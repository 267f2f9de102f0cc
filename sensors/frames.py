"""Sensor mounting and frames: where a sensor sits on the ego and how that maps to the world.

The ego's pose is a hiyari.kinematics.Pose (``WorldState.pose_of(ego_id)``).

Ego frame: x forward, y left, z up, origin at the centre of the ego's ground rectangle (the
WorldState ``xyz``). Sensor frame: x along the boresight, y left, z up. Angles of a mount in
degrees: yaw positive to the left, pitch positive nose-down, roll positive right side down
(right-handed rotations about z, y and x, applied in that order).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.kinematics import Pose


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


def sensor_to_world(mount: Mount, ego: Pose) -> np.ndarray:
    """(4, 4) transform from the sensor frame to network coordinates (the ego flat: no pitch
    or roll)."""
    return ego.to_world() @ mount.sensor_to_ego()
