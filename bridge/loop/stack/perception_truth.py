"""Ground-truth perception: what a perfect sensor suite would report (and a disabled one)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.kinematics import Pose
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.world_state import WorldState


@dataclass(frozen=True)
class PerfectPerception:
    """Every actor within ``max_range`` metres and ``fov_deg`` of the ego's heading, exactly.

    No occlusion, no noise: the upper bound a sensor suite can reach.
    """

    max_range: float = 150.0
    fov_deg: float = 180.0

    def perceive(self, world: WorldState, ego_row: int, ego: Pose) -> list[ObjectList]:
        """One ObjectList ("truth") in the ego frame, velocities relative to the ego."""
        others = np.arange(len(world)) != ego_row
        rel = ego.world_to_vehicle(world.xyz[:, :2])
        rng = np.hypot(rel[:, 0], rel[:, 1])
        bearing = np.degrees(np.abs(np.arctan2(rel[:, 1], rel[:, 0])))
        keep = others & (rng <= self.max_range) & (bearing <= self.fov_deg / 2)
        idx = np.flatnonzero(keep)
        vel = ego.world_to_vehicle_vec(world.velocity[idx] - ego.velocity)
        n = len(idx)
        pos = np.zeros((n, 3))
        pos[:, :2] = rel[idx]
        v3 = np.zeros((n, 3))
        v3[:, :2] = vel
        size = np.stack([world.length[idx], world.width[idx], world.height[idx]], 1)
        # relative heading lets fusion keep the footprint's orientation
        return [
            ObjectList(
                time=world.time,
                source="truth",
                frame_to_world=ego.to_world(),
                object_id=idx.astype(np.int64),
                cls=world.cls[idx].astype(np.int8),
                position=pos,
                velocity=v3,
                size=size,
                confidence=np.ones(n),
                truth=world.ids[idx].copy(),
            )
        ]


@dataclass(frozen=True)
class NoPerception:
    """Sensors disabled: nothing is ever perceived (the ego cannot react)."""

    def perceive(self, world: WorldState, ego_row: int, ego: Pose) -> list[ObjectList]:
        return [ObjectList.empty(world.time, "none", ego.to_world())]
