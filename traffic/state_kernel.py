"""Compiled per-step kernels of the WorldState read: SUMO's values to the state's arrays, and
the read scope's radius test.

A step's state has a few dozen to a few hundred rows, where numpy's per-call overhead (some
forty array operations per read) outweighs the arithmetic: one compiled pass does it all.
Each kernel computes exactly what its numpy reference does, operation for operation
(tests/unit/traffic/test_traffic_state_kernel.py checks them bit for bit).
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.jit import njit


@njit(cache=True)
def sumo_to_state(
    front: np.ndarray,
    angle: np.ndarray,
    speed: np.ndarray,
    accel: np.ndarray,
    vehicle_static: np.ndarray,
    vehicle_rows: np.ndarray,
    person_static: np.ndarray,
    person_rows: np.ndarray,
    history: np.ndarray,
    now: float,
    before: float,
    dt: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(xyz, heading, static values) of N actors from SUMO's values.

    N actors: the vehicles, then the persons. ``front`` (N, 3) SUMO positions (vehicle
    front-bumper centres), m; ``angle`` (N,) SUMO compass angles, degrees; ``speed`` (N,) m/s;
    ``accel`` (N,) m/s^2 holds the vehicles' accelerations. ``*_static`` (K, 4) class, length,
    width, height of an actor table and ``*_rows`` each actor's row in it. The persons'
    accelerations (rows of ``history`` (K, 4): time and speed of the latest read, of the one
    before) are filled in as (speed - speed read at ``before``) / ``dt``, 0 where not read
    then, and ``history`` records ``speed`` at ``now`` (s). Returns the ground-rectangle
    centres (N, 3) m, headings (N,) rad counter-clockwise from +x in (-pi, pi], and the
    actors' static values (N, 4).
    """
    n = front.shape[0]
    xyz = np.empty((n, 3))
    heading = np.empty(n)
    st = np.empty((n, 4))
    nv = vehicle_rows.shape[0]
    for i in range(n):
        a = np.radians(90.0 - angle[i])
        h = math.atan2(math.sin(a), math.cos(a))
        heading[i] = h
        st[i] = vehicle_static[vehicle_rows[i]] if i < nv else person_static[person_rows[i - nv]]
        d = -0.5 * st[i, 1]
        xyz[i, 0] = front[i, 0] + d * math.cos(h)
        xyz[i, 1] = front[i, 1] + d * math.sin(h)
        xyz[i, 2] = front[i, 2]
    for i in range(nv, n):
        r = person_rows[i - nv]
        if history[r, 0] != now:  # a second read at the same time keeps the first's history
            history[r, 2] = history[r, 0]
            history[r, 3] = history[r, 1]
        history[r, 0] = now
        history[r, 1] = speed[i]
        accel[i] = (speed[i] - history[r, 3]) / dt if history[r, 2] == before else 0.0
    return xyz, heading, st


@njit(cache=True)
def within(xyz: np.ndarray, cx: float, cy: float, radius: float) -> np.ndarray:
    """(N,) bool: the points ``xyz`` (N, >=2) within ``radius`` (2-D, hypot) of (cx, cy), m."""
    n = xyz.shape[0]
    out = np.empty(n, np.bool_)
    for i in range(n):
        out[i] = math.hypot(xyz[i, 0] - cx, xyz[i, 1] - cy) <= radius
    return out
