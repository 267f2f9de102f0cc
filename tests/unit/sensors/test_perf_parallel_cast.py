"""Casting in parallel chunks gives the same hits, bit for bit, as one sequential cast."""

from __future__ import annotations

import numpy as np

from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.scene.ray_scene import CAST_CHUNK, RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, street_scenario


def test_parallel_chunks_equal_sequential_cast_and_scan() -> None:
    world = street_scenario(occluder=True)
    mesh = StraightRoad().mesh()
    one, two = RayScene(mesh), RayScene(mesh, workers=2)
    lidar = Lidar(LidarConfig.preset("64ch"), Mount(x=0.0, z=1.9))
    assert lidar.config.rays > 4 * CAST_CHUNK  # the scan is really split
    clouds = []
    for scene in (one, two):
        scene.update(world, "ego")
        rng = np.random.default_rng(7)
        clouds.append(lidar.scan(scene, world.pose_of("ego"), world, Environment(), rng))
        rng = np.random.default_rng(1)
        dirs = rng.normal(size=(3 * CAST_CHUNK + 5, 3)).astype(np.float32)
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        origins = np.tile(np.float32([0.0, -1.75, 1.5]), (len(dirs), 1))
        hits = scene.cast(origins, dirs, 150.0, normals=True)
        clouds.append(hits)
    a, b = clouds[0], clouds[2]
    assert len(a) > 50_000 and np.sum(a.hit >= 0) > 500
    for name in ("xyz", "intensity", "range", "hit"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    h1, h2 = clouds[1], clouds[3]
    assert np.sum(h1.hit >= 0) > 0
    for name in ("distance", "hit", "material", "cos_incidence", "normal"):
        assert np.array_equal(getattr(h1, name), getattr(h2, name)), name
