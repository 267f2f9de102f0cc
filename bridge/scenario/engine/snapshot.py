"""What the trigger conditions read at one step, gathered from the WorldState and the
scripted actors' table in compiled passes: per entity (scenario order) presence, box centre,
reference point, heading, speed, acceleration and road coordinates.

Frames and units: world x, y in metres, headings in radians from world +x, speeds m/s; road
s, t in metres (t left of the reference line), ``road_dir`` +1 / -1 along s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit


@dataclass
class Snapshot:
    """What conditions read at one step: per entity (index in the scenario's entity order)
    the reference point, box centre, heading (rad), sizes (m), speed (m/s), acceleration,
    presence, road coordinates of the box centre, and the contacts (entity index pairs)."""

    time: float
    present: np.ndarray  # (E,) bool
    ref: np.ndarray  # (E, 2)
    centre: np.ndarray  # (E, 2)
    heading: np.ndarray
    length: np.ndarray
    width: np.ndarray
    speed: np.ndarray
    accel: np.ndarray
    on_net: np.ndarray  # (E,) bool: on a SUMO lane
    road_s: np.ndarray  # (E,) s of the box centre (nan: unknown)
    road_t: np.ndarray
    road_dir: np.ndarray  # (E,) +1 / -1 driving direction along s
    contacts: set[frozenset[int]]
    contact_any: np.ndarray  # (E,) bool


@njit(cache=True)
def gather_entities(
    rows: np.ndarray,
    xyz: np.ndarray,
    heading: np.ndarray,
    speed: np.ndarray,
    accel: np.ndarray,
    centre_offset: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per entity (``rows``: its row in the WorldState arrays, -1 absent): (present, box
    centre (E, 2), reference point (E, 2) = centre - ``centre_offset`` in the vehicle frame,
    heading, speed, accel). Absent entities read WorldState row 0 (or zeros when empty), as
    their measures are discarded."""
    n = len(rows)
    present = np.zeros(n, dtype=np.bool_)
    centre, ref = np.zeros((n, 2)), np.zeros((n, 2))
    h, v, acc = np.zeros(n), np.zeros(n), np.zeros(n)
    for i in range(n):
        r = rows[i]
        present[i] = r >= 0
        if r < 0:
            if len(heading) == 0:
                continue
            r = 0
        centre[i, 0], centre[i, 1] = xyz[r, 0], xyz[r, 1]
        h[i], v[i], acc[i] = heading[r], speed[r], accel[r]
        c, s = math.cos(h[i]), math.sin(h[i])
        px, py = -centre_offset[i, 0], -centre_offset[i, 1]  # vehicle_to_world(-offset, ...)
        ref[i, 0] = (px * c - py * s) + centre[i, 0]
        ref[i, 1] = (px * s + py * c) + centre[i, 1]
    return present, centre, ref, h, v, acc


@njit(cache=True)
def own_road_coords(
    own: np.ndarray,
    present: np.ndarray,
    road_code: np.ndarray,
    s: np.ndarray,
    t: np.ndarray,
    direction: np.ndarray,
    cx: np.ndarray,
    road_s: np.ndarray,
    road_t: np.ndarray,
    road_dir: np.ndarray,
) -> None:
    """Road s of the box centre (reference s plus ``cx``, the centre's offset ahead of the
    reference point, along the driving direction), t and direction of the ``own`` and
    ``present`` rows of the actor table that are on a road (``road_code`` >= 0), into the
    last three arrays; NaN, NaN, 1 for the others."""
    for k in range(len(own)):
        if own[k] and present[k] and road_code[k] >= 0:
            road_dir[k] = direction[k]
            road_s[k] = s[k] + direction[k] * cx[k]
            road_t[k] = t[k]
        else:
            road_s[k], road_t[k], road_dir[k] = np.nan, np.nan, 1.0
