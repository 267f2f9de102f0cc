"""The LiDAR scan's compiled passes equal the numpy formulas they replace, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.kinematics import rotate_xy
from hiyari.sensors.lidar.scan_kernel import add_range_noise, return_points, scan_rays

#: compiled kernels against numpy formulas: CI runs these again with numpy's dispatch limited
pytestmark = pytest.mark.kernels


def _unit(rng: np.random.Generator, n: int) -> np.ndarray:
    d = rng.normal(size=(n, 3))
    return (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)


def test_scan_rays_equal_numpy():
    rng = np.random.default_rng(11)
    n = 4096
    ego = _unit(rng, n)
    x, y, z = (np.ascontiguousarray(ego[:, k]) for k in range(3))
    fire = rng.uniform(0.0, 0.1, n).astype(np.float32)
    origin = np.array([1234.5, -987.25, 1.9])
    for heading, velocity in ((0.7, np.array([12.3, -4.5, 0.0])), (-2.9, np.zeros(3))):
        cs = (np.float32(np.cos(heading)), np.float32(np.sin(heading)))
        moving = bool(np.any(velocity))
        dirs, origins = scan_rays(
            (x, y, z), cs, origin.astype(np.float32), velocity.astype(np.float32), fire, moving
        )
        want = np.empty((n, 3), np.float32)
        want[:, 0], want[:, 1] = rotate_xy(x, y, heading)
        want[:, 2] = z
        assert np.array_equal(dirs, want)
        o = np.empty((n, 3), np.float32)
        for k in range(3):
            o[:, k] = np.float32(origin[k]) + fire * np.float32(velocity[k])
        assert np.array_equal(origins, o)
        # at rest every ray starts at the sensor
        assert moving or (origins == origin.astype(np.float32)).all()


def test_return_points_and_range_noise_equal_numpy():
    rng = np.random.default_rng(5)
    directions = _unit(rng, 2000)
    ray = np.sort(rng.choice(2000, 700, replace=False)).astype(np.int64)
    r = rng.uniform(0.2, 150.0, 700).astype(np.float32)
    xyz = return_points(directions, ray, r)
    want = np.take(directions, ray, axis=0)
    want *= r[:, None]
    assert xyz.dtype == np.float32 and np.array_equal(xyz, want)

    draws = rng.standard_normal(700, dtype=np.float32)
    sigma, least = np.float32(0.5), np.float32(0.3)
    noisy_want = np.maximum(r + sigma * draws, least)
    want *= (noisy_want / r)[:, None]
    noisy = add_range_noise(xyz, r, sigma, draws, least)
    assert np.array_equal(noisy, noisy_want) and np.array_equal(xyz, want)
    assert noisy.min() >= least  # clamped at the least range
    assert np.allclose(np.linalg.norm(xyz, axis=1), noisy, rtol=1e-5)
