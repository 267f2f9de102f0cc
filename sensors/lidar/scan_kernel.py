"""Compiled per-ray passes of a LiDAR scan: the rays' network-frame directions and origins,
the returns' points, and the range noise.

Each is one loop over the scan's rays or returns instead of numpy's chain of temporaries; the
arithmetic is numpy's float32 arithmetic of the formulas in sensors/lidar/sensor.py, in the
same order (tests/unit/sensors/test_lidar_scan_kernel.py checks them equal bit for bit).
"""

from __future__ import annotations

import numpy as np

from hiyari.jit import njit


@njit(cache=True, nogil=True)
def scan_rays(
    ego_xyz: tuple[np.ndarray, np.ndarray, np.ndarray],
    cos_sin: tuple[np.float32, np.float32],
    origin: np.ndarray,
    velocity: np.ndarray,
    fire_time: np.ndarray,
    moving: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3) float32 ray directions yawed from the ego frame (``ego_xyz`` components) by the
    heading's ``cos_sin``, and (N, 3) float32 ray origins: the sensor ``origin`` (3,) float32,
    when ``moving`` moved by ``velocity`` (3,) float32 (m/s, network frame) over each ray's
    ``fire_time`` (s)."""
    x, y, z = ego_xyz
    c, s = cos_sin
    n = len(x)
    dirs = np.empty((n, 3), np.float32)
    origins = np.empty((n, 3), np.float32)
    for p in range(n):
        dirs[p, 0] = x[p] * c - y[p] * s
        dirs[p, 1] = x[p] * s + y[p] * c
        dirs[p, 2] = z[p]
        for k in range(3):
            if moving:
                origins[p, k] = origin[k] + fire_time[p] * velocity[k]
            else:
                origins[p, k] = origin[k]
    return dirs, origins


@njit(cache=True, nogil=True)
def return_points(directions: np.ndarray, ray: np.ndarray, r: np.ndarray) -> np.ndarray:
    """(M, 3) float32 points ``r`` m along the sensor-frame ``directions`` of rays ``ray``."""
    xyz = np.empty((len(ray), 3), np.float32)
    for i in range(len(ray)):
        for k in range(3):
            xyz[i, k] = directions[ray[i], k] * r[i]
    return xyz


@njit(cache=True, nogil=True)
def add_range_noise(
    xyz: np.ndarray, r: np.ndarray, sigma: np.float32, draws: np.ndarray, min_range: np.float32
) -> np.ndarray:
    """Ranges ``r`` plus ``sigma`` x standard normal ``draws`` (m), at least ``min_range``;
    the points ``xyz`` (M, 3) are scaled to them in place. Returns the new ranges."""
    noisy = np.empty_like(r)
    for i in range(len(r)):
        v = max(r[i] + sigma * draws[i], min_range)
        scale = v / r[i]
        for k in range(3):
            xyz[i, k] *= scale
        noisy[i] = v
    return noisy
