"""The ego vehicle's frame: x forward, y left, z up, origin at its ground-rectangle centre."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.traffic.world_state import WorldState


@dataclass(frozen=True)
class EgoPose:
    """Ego state read from a WorldState row. Network metres, radians, m/s."""

    x: float
    y: float
    z: float
    heading: float
    speed: float
    accel: float
    length: float
    width: float

    @staticmethod
    def from_world(world: WorldState, row: int) -> EgoPose:
        """The ego's pose at ``row`` of ``world``."""
        return EgoPose(
            float(world.xyz[row, 0]),
            float(world.xyz[row, 1]),
            float(world.xyz[row, 2]),
            float(world.heading[row]),
            float(world.speed[row]),
            float(world.accel[row]),
            float(world.length[row]),
            float(world.width[row]),
        )

    def to_world(self) -> np.ndarray:
        """(4, 4) transform from the ego frame to network coordinates."""
        c, s = np.cos(self.heading), np.sin(self.heading)
        m = np.eye(4)
        m[:2, :2] = [[c, -s], [s, c]]
        m[:3, 3] = [self.x, self.y, self.z]
        return m

    def world_to_ego_xy(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) network points -> ego frame."""
        c, s = np.cos(self.heading), np.sin(self.heading)
        d = np.asarray(xy, dtype=float) - [self.x, self.y]
        return np.stack([d[:, 0] * c + d[:, 1] * s, -d[:, 0] * s + d[:, 1] * c], 1)

    def world_to_ego_vec(self, v: np.ndarray) -> np.ndarray:
        """(N, 2) network-frame vectors -> ego axes (no translation)."""
        c, s = np.cos(self.heading), np.sin(self.heading)
        v = np.asarray(v, dtype=float)
        return np.stack([v[:, 0] * c + v[:, 1] * s, -v[:, 0] * s + v[:, 1] * c], 1)

    @property
    def velocity(self) -> np.ndarray:
        """(2,) velocity in the network frame, m/s."""
        return self.speed * np.array([np.cos(self.heading), np.sin(self.heading)])


def frame_points_to_ego(frame_to_world: np.ndarray, pts: np.ndarray, ego: EgoPose) -> np.ndarray:
    """(N, 3) points in a sensor/object frame -> (N, 2) ego-frame x, y."""
    pts = np.asarray(pts, dtype=float).reshape(-1, 3)
    world = pts @ frame_to_world[:3, :3].T + frame_to_world[:3, 3]
    return ego.world_to_ego_xy(world[:, :2])
