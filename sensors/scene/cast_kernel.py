"""Compiled passes of the ray-cast scene over every ray of a cast.

``static_hits`` turns Embree's static-scene answer into the per-ray hit tables, and
``actor_candidates`` picks the rays that may reach an actor: one loop each instead of numpy's
chain of gathers and temporaries over 131k rays. The arithmetic is numpy's float32 arithmetic
of the same formulas, in the same order (tests/e2e/sensors/test_sensors_scene.py checks them equal bit for
bit against the numpy reference beside each kernel). Both release the GIL so that the cast
threads run them in parallel.
"""

from __future__ import annotations

import numpy as np

from hiyari.jit import njit
from hiyari.sensors.outputs import HIT_NONE, HIT_STATIC


@njit(cache=True, nogil=True)
def static_hits(
    prim: np.ndarray,
    tfar: np.ndarray,
    directions: np.ndarray,
    tables: tuple[np.ndarray, np.ndarray],
    out: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> None:
    """Fill ``out`` = (distance, hit, material, cos_incidence, normal) for rays whose static
    primitive is ``prim`` (-1: a miss) at ``tfar`` m along unit ``directions`` (N, 3) float32.

    ``tables`` = (material per static face plus a last NO_MATERIAL row, unit normal per face
    plus a last zero row). ``normal`` is (N, 3) to receive the normal facing the ray, or
    (0, 3) when not wanted. Misses get inf, HIT_NONE, the tables' last row and 0.
    """
    material_ext, normal_ext = tables
    distance, hit, material, cos_incidence, normal = out
    last = len(material_ext) - 1
    with_normal = len(normal) > 0
    inf = np.float32(np.inf)
    plus, minus = np.float32(1.0), np.float32(-1.0)
    for p in range(len(prim)):
        k = prim[p]
        if k >= 0:
            distance[p] = tfar[p]
            hit[p] = HIT_STATIC
        else:
            k = last
            distance[p] = inf
            hit[p] = HIT_NONE
        material[p] = material_ext[k]
        n0, n1, n2 = normal_ext[k, 0], normal_ext[k, 1], normal_ext[k, 2]
        dot = n0 * directions[p, 0] + n1 * directions[p, 1] + n2 * directions[p, 2]
        cos_incidence[p] = abs(dot)
        if with_normal:
            sign = minus if dot > 0 else plus
            normal[p, 0], normal[p, 1], normal[p, 2] = n0 * sign, n1 * sign, n2 * sign


@njit(cache=True, nogil=True)
def actor_candidates(
    distance: np.ndarray,
    ray_bin: np.ndarray,
    elevation: np.ndarray,
    bins: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> np.ndarray:
    """Indices (ascending) of the rays that may hit an actor: the static hit ``distance`` lies
    beyond the nearest actor sphere of the ray's azimuth bin and its ``elevation`` is inside
    that bin's span. ``bins`` = (nearest distance, lowest and highest elevation per bin)."""
    near, low, high = bins
    idx = np.empty(len(distance), np.int64)
    m = 0
    for p in range(len(distance)):
        b = ray_bin[p]
        if distance[p] > near[b] and elevation[p] >= low[b] and elevation[p] <= high[b]:
            idx[m] = p
            m += 1
    return idx[:m]
