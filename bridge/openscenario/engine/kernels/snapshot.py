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

from hiyari.bridge.openscenario.engine.kernels.motion_kernel import S, T
from hiyari.jit import njit


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


#: Rows of the per-entity float matrix the snapshot kernel fills: heading (rad), speed (m/s),
#: acceleration (m/s^2), road s of the box centre, road t (m) and driving direction (+1 / -1).
F_HEADING, F_SPEED, F_ACCEL, F_ROAD_S, F_ROAD_T, F_ROAD_DIR = range(6)


@njit(cache=True)
def gather_entities(
    rows: np.ndarray,
    xyz: np.ndarray,
    heading: np.ndarray,
    speed: np.ndarray,
    accel: np.ndarray,
    centre_offset: np.ndarray,
    own: np.ndarray,
    road_code: np.ndarray,
    table: np.ndarray,
    direction: np.ndarray,
    present: np.ndarray,
    centre: np.ndarray,
    ref: np.ndarray,
    out: np.ndarray,
) -> None:
    """Per entity (``rows``: its row in the WorldState arrays, -1 absent), into the last four
    arrays (reused from step to step: no allocation): present (E,), box centre (E, 2),
    reference point (E, 2) = centre - ``centre_offset`` in the vehicle frame, and the rows
    ``F_*`` of ``out`` (6, E). Absent entities read WorldState row 0 (or zeros when empty), as
    their measures are discarded. Road coordinates: those of the ``own`` and present rows of
    the actor table on a road (``road_code`` >= 0; ``table``: its state matrix, s and t in
    rows ``motion_kernel.S`` / ``T``) with the centre ``centre_offset[:, 0]`` ahead of the
    reference point along the driving direction; NaN, NaN, 1 for the others."""
    n = len(rows)
    for i in range(n):
        r = rows[i]
        present[i] = r >= 0
        if r < 0:
            if len(heading) == 0:
                centre[i, 0] = centre[i, 1] = ref[i, 0] = ref[i, 1] = 0.0
                out[F_HEADING, i] = out[F_SPEED, i] = out[F_ACCEL, i] = 0.0
                _road_coords(i, own, present, road_code, table, direction, centre_offset, out)
                continue
            r = 0
        centre[i, 0], centre[i, 1] = xyz[r, 0], xyz[r, 1]
        h = heading[r]
        out[F_HEADING, i], out[F_SPEED, i], out[F_ACCEL, i] = h, speed[r], accel[r]
        c, s = math.cos(h), math.sin(h)
        px, py = -centre_offset[i, 0], -centre_offset[i, 1]  # vehicle_to_world(-offset, ...)
        ref[i, 0] = (px * c - py * s) + centre[i, 0]
        ref[i, 1] = (px * s + py * c) + centre[i, 1]
        _road_coords(i, own, present, road_code, table, direction, centre_offset, out)


@njit(cache=True, inline="always")
def _road_coords(
    k: int,
    own: np.ndarray,
    present: np.ndarray,
    road_code: np.ndarray,
    table: np.ndarray,
    direction: np.ndarray,
    centre_offset: np.ndarray,
    out: np.ndarray,
) -> None:
    """Road s of entity ``k``'s box centre, t and direction from the actor table (see
    :func:`gather_entities`)."""
    if own[k] and present[k] and road_code[k] >= 0:
        out[F_ROAD_DIR, k] = direction[k]
        out[F_ROAD_S, k] = table[S, k] + direction[k] * centre_offset[k, 0]
        out[F_ROAD_T, k] = table[T, k]
    else:
        out[F_ROAD_S, k], out[F_ROAD_T, k], out[F_ROAD_DIR, k] = np.nan, np.nan, 1.0
