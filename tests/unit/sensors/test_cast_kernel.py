"""The ray-cast scene's compiled passes equal their numpy reference bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.net.mesh.materials import Material
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.outputs import HIT_NONE, HIT_STATIC
from hiyari.sensors.scene.cast_kernel import actor_candidates, static_hits
from hiyari.sensors.scene.ray_scene import AZIMUTH_BINS, NO_MATERIAL, RayScene, SensorRays
from hiyari.sensors.scene.synthetic import actor_world, wall
from hiyari.traffic.actor_class import ActorClass

#: compiled kernels against numpy formulas: CI runs these again with numpy's dispatch limited
pytestmark = pytest.mark.kernels


def _numpy_static(prim, tfar, d, material_ext, normal_ext):
    """The numpy formulas the kernel replaces (ray_scene before the kernel)."""
    found = prim >= 0
    nrm = np.take(normal_ext, prim, axis=0)
    dot = nrm[:, 0] * d[:, 0] + nrm[:, 1] * d[:, 1] + nrm[:, 2] * d[:, 2]
    return (
        np.where(found, tfar, np.float32(np.inf)),
        np.where(found, np.int32(HIT_STATIC), np.int32(HIT_NONE)),
        np.take(material_ext, prim),
        np.abs(dot),
        nrm * np.where(dot > 0, np.float32(-1), np.float32(1))[:, None],
    )


def test_static_hits_equal_numpy_bit_for_bit():
    rng = np.random.default_rng(7)
    n, faces = 5000, 40
    prim = rng.integers(-1, faces, n).astype(np.int32)
    tfar = rng.uniform(0.5, 200.0, n).astype(np.float32)
    d = rng.normal(size=(n, 3))
    d = (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
    material_ext = np.append(rng.integers(0, 10, faces).astype(np.uint8), np.uint8(NO_MATERIAL))
    normal_ext = np.zeros((faces + 1, 3), np.float32)
    nrm = rng.normal(size=(faces, 3))
    normal_ext[:-1] = nrm / np.linalg.norm(nrm, axis=1, keepdims=True)
    out = (
        np.empty(n, np.float32),
        np.empty(n, np.int32),
        np.empty(n, np.uint8),
        np.empty(n, np.float32),
        np.empty((n, 3), np.float32),
    )
    static_hits(prim, tfar, d, (material_ext, normal_ext), out)
    for got, want in zip(out, _numpy_static(prim, tfar, d, material_ext, normal_ext), strict=True):
        assert got.dtype == want.dtype
        assert np.array_equal(got, want)
    assert np.isinf(out[0][prim < 0]).all() and (out[2][prim < 0] == NO_MATERIAL).all()
    # without normals the other tables are the same
    short = tuple(np.empty_like(a) for a in out[:4])
    static_hits(prim, tfar, d, (material_ext, normal_ext), (*short, np.zeros((0, 3), np.float32)))
    assert all(np.array_equal(a, b) for a, b in zip(short, out[:4], strict=False))


def test_actor_candidates_equal_numpy_mask():
    rng = np.random.default_rng(3)
    n = 20000
    distance = rng.uniform(0.0, 100.0, n).astype(np.float32)
    distance[::7] = np.inf
    ray_bin = rng.integers(0, AZIMUTH_BINS, n).astype(np.int32)
    elevation = rng.uniform(-0.4, 0.3, n).astype(np.float32)
    near = np.where(rng.random(AZIMUTH_BINS) < 0.3, rng.uniform(0, 80, AZIMUTH_BINS), np.inf)
    low = rng.uniform(-0.5, 0.0, AZIMUTH_BINS)
    high = low + rng.uniform(0.0, 0.4, AZIMUTH_BINS)
    bins = tuple(a.astype(np.float32) for a in (near, low, high))
    want = np.flatnonzero(
        (distance > np.take(bins[0], ray_bin))
        & (elevation >= np.take(bins[1], ray_bin))
        & (elevation <= np.take(bins[2], ray_bin))
    )
    got = actor_candidates(distance, ray_bin, elevation, bins)
    assert 0 < len(got) < n
    assert np.array_equal(got, want)


def test_scene_cast_same_hits_for_any_number_of_workers():
    """A real LiDAR scan through the compiled passes, split over 1 and 2 threads."""
    scene_mesh = wall(30.0, -40.0, 40.0, 6.0, Material.BUILDING)
    world = actor_world(
        [
            dict(id="ego", cls=ActorClass.CAR, x=0, y=0),
            dict(id="car", cls=ActorClass.CAR, x=12.0, y=1.0),
            dict(id="kid", cls=ActorClass.PEDESTRIAN, x=8.0, y=-3.0),
        ]
    )
    lidar = Lidar(LidarConfig.preset("64ch"), Mount(z=1.9))
    s2w = lidar.sensor_to_world(world.pose_of("ego"))
    dirs = (lidar.directions.astype(np.float64) @ s2w[:3, :3].T).astype(np.float32)
    origins = np.empty_like(dirs)
    origins[:] = s2w[:3, 3].astype(np.float32)
    rays = SensorRays(lidar.index, s2w[:3, 3], s2w[:3, :3])
    casts = []
    for workers in (1, 2):
        scene = RayScene(scene_mesh, workers=workers)
        scene.update(world, "ego")
        casts.append(scene.cast(origins, dirs, 120.0, rays, normals=True))
    one, two = casts
    for field in ("distance", "hit", "material", "cos_incidence", "normal"):
        assert np.array_equal(getattr(one, field), getattr(two, field))
    assert {HIT_STATIC, HIT_NONE, 1, 2} <= set(one.hit.tolist())
    wall_hits = one.hit == HIT_STATIC
    assert (one.material[wall_hits] == Material.BUILDING).all()
    # a ray straight at the wall's face meets it at normal incidence
    assert one.cos_incidence[wall_hits].max() > 0.999
