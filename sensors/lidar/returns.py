"""Compiled LiDAR return pass: received intensity, detection threshold and points in one loop.

One pass over the cast rays replaces numpy's chain of gathers and temporaries; the arithmetic
is numpy's float32 arithmetic of the formula in sensors/lidar/sensor.py, in the same order.
"""

from __future__ import annotations

import numpy as np

from hiyari.jit import njit
from hiyari.sensors.outputs import HIT_NONE


@njit(cache=True)
def detected_returns(
    hit: np.ndarray,
    distance: np.ndarray,
    material: np.ndarray,
    cos_incidence: np.ndarray,
    optics: tuple[np.ndarray, np.ndarray, np.ndarray],
    lobe2: np.float32,
    two_alpha: np.float32,
    limits: tuple[np.float32, np.float32],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rays whose return is detected, their range (m) and intensity (1 = white Lambertian at
    1 m, normal incidence).

    ``optics`` = (diffuse reflectance per material, specular peak gain per material, two-way
    window transmission per ray); ``lobe2`` the squared specular lobe width (rad^2);
    ``two_alpha`` twice the extinction coefficient (1/m, 0 in clear air); ``limits`` = (least
    intensity, least range in m). All float32.
    """
    diffuse, peak, soil_t2 = optics
    min_intensity, min_range = limits
    n = len(hit)
    ray = np.empty(n, np.int64)
    rng = np.empty(n, np.float32)
    inten = np.empty(n, np.float32)
    one, floor = np.float32(1.0), np.float32(1e-3)
    minus_two = np.float32(-2.0)
    m = 0
    for p in range(n):
        if hit[p] == HIT_NONE:
            continue
        r = distance[p]
        mat = material[p]
        cos = cos_incidence[p]
        i = diffuse[mat] * cos
        if peak[mat] > 0:
            cg = max(cos, floor)
            tan2 = (one - cg * cg) / (cg * cg)
            i += peak[mat] * np.exp(minus_two * tan2 / lobe2)
        i /= r * r
        i *= soil_t2[p]
        if two_alpha > 0:
            i *= np.exp(-two_alpha * r)
        if i >= min_intensity and r >= min_range:
            ray[m], rng[m], inten[m] = p, r, i
            m += 1
    return ray[:m], rng[:m], inten[:m]
