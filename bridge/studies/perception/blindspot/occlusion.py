"""Is the hidden vehicle hidden? The visible-ray fraction from the ego's ray-cast LiDAR.

The LiDAR scans the initial scene twice with Embree, with and without the occluding truck;
the visible-ray fraction is the number of returns on the hidden vehicle with the truck over the
number without it (1: fully visible, 0: fully hidden). The road surface is left out: on the flat
road it occludes nothing between vehicles.
"""

from __future__ import annotations

import numpy as np

from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.traffic.world_state import WorldState

HIDDEN_BELOW = 0.2
"""A vehicle counts as hidden when fewer than 20 % of the LiDAR returns it would give in clear
view reach it (toolkit choice: the remainder is a sliver a few points wide)."""


class OcclusionProbe:
    """The ego's roof LiDAR (64 channels, 360 deg) over an empty static scene."""

    def __init__(self, lidar: LidarConfig | None = None) -> None:
        empty = SceneMesh(np.zeros((0, 3)), np.zeros((0, 3), np.int32), np.zeros(0, np.uint8))
        self.scene = RayScene(empty)
        self.lidar = Lidar(lidar or LidarConfig.preset("64ch"), Mount(x=0.0, z=1.9))

    def returns_on(self, world: WorldState, target: str) -> int:
        """LiDAR returns on actor ``target`` with the ego's sensor at world 'ego'."""
        self.scene.update(world, "ego")
        ego = world.pose_of("ego")
        cloud, _ = self.lidar.sense(self.scene, ego, world, Environment(), np.random.default_rng(0))
        row = int(np.flatnonzero(world.ids == target)[0])
        return int(np.sum(cloud.hit == row))

    def visible_fraction(self, world: WorldState, target: str, occluder: str) -> float:
        """Returns on ``target`` with ``occluder`` present over those without it (0..1)."""
        alone = self.returns_on(world.select(world.ids != occluder), target)
        if alone == 0:
            return 0.0
        return self.returns_on(world, target) / alone


def deepest_occlusion(probe: OcclusionProbe, worlds: list[WorldState]) -> tuple[int, float]:
    """Index of the candidate start world whose hidden car is least visible, and its visible-ray
    fraction (ids 'ego', 'occluder', 'hidden')."""
    fractions = [probe.visible_fraction(w, "hidden", "occluder") for w in worlds]
    best = int(np.argmin(fractions))
    return best, fractions[best]
