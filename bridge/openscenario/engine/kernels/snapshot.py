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

from hiyari.bridge.openscenario.engine.kernels.motion_kernel import S, T, V
from hiyari.bridge.openscenario.engine.kernels.tables import (
    ActorArrays,
    EntityFields,
    GatherArrays,
    WorldArrays,
)
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
    #: (E,) each road's code in the ActorTable's road_ids (-1: none; None: all -1)
    road_code: np.ndarray | None = None


#: Rows of the engine's per-entity float matrix (one allocation; its EntityFields and
#: Snapshot hold the rows): heading (rad), speed (m/s), acceleration (m/s^2), road s of the
#: box centre, road t (m), driving direction (+1 / -1) and road (its code in the
#: ActorTable's ``road_ids``; -1: none).
F_HEADING, F_SPEED, F_ACCEL, F_ROAD_S, F_ROAD_T, F_ROAD_DIR, F_ROAD_CODE = range(7)


@njit(cache=True)
def gather_entities(
    world: WorldArrays, ent: GatherArrays, actors: ActorArrays, out: EntityFields
) -> None:
    """Per entity (``ent.rows``: its row in the ``world`` arrays, -1 absent), into ``out``
    (its arrays reused from step to step: no allocation): present, box centre, reference
    point = centre - ``centre_offset`` in the vehicle frame, heading, speed and acceleration
    along the heading (negative for a reversing ``driven`` entity) and road coordinates.
    Absent entities read WorldState row 0 (or zeros when empty), as their measures are
    discarded. Road coordinates: those of the ``own`` and present rows of the
    ActorTable (``actors``) on a road, with the centre ``centre_offset[:, 0]`` ahead of the
    reference point along the driving direction; NaN, NaN, 1 for the others."""
    world, ent, actors = WorldArrays(*world), GatherArrays(*ent), ActorArrays(*actors)
    out = EntityFields(*out)
    rows, offset = ent.rows, ent.centre_offset
    present, centre, ref = out.present, out.centre, out.ref
    heading = world.heading
    for i in range(len(rows)):
        r = rows[i]
        present[i] = r >= 0
        if r < 0:
            if len(heading) == 0:
                centre[i, 0] = centre[i, 1] = ref[i, 0] = ref[i, 1] = 0.0
                out.heading[i] = out.speed[i] = out.accel[i] = 0.0
                _road_coords(i, ent, actors, out)
                continue
            r = 0
        centre[i, 0], centre[i, 1] = world.xyz[r, 0], world.xyz[r, 1]
        h = heading[r]
        out.heading[i], out.speed[i], out.accel[i] = h, world.speed[r], world.accel[r]
        if ent.driven[i] and actors.state[V, i] < 0.0:
            # reversing: SUMO's speed is the magnitude and its acceleration d|v|/dt; the
            # entity's velocity along its heading is negative
            out.speed[i], out.accel[i] = -world.speed[r], -world.accel[r]
        c, s = math.cos(h), math.sin(h)
        px, py = -offset[i, 0], -offset[i, 1]  # vehicle_to_world(-offset, ...)
        ref[i, 0] = (px * c - py * s) + centre[i, 0]
        ref[i, 1] = (px * s + py * c) + centre[i, 1]
        _road_coords(i, ent, actors, out)


@njit(cache=True)
def _road_coords(k: int, ent: GatherArrays, actors: ActorArrays, out: EntityFields) -> None:
    """Road s of entity ``k``'s box centre, t and direction from the ActorTable (see
    :func:`gather_entities`)."""
    if ent.own[k] and out.present[k] and actors.road_code[k] >= 0:
        d = actors.direction[k]
        out.road_dir[k] = d
        out.road_s[k] = actors.state[S, k] + d * ent.centre_offset[k, 0]
        out.road_t[k] = actors.state[T, k]
        out.road_code[k] = actors.road_code[k]
    else:
        out.road_s[k], out.road_t[k], out.road_dir[k] = np.nan, np.nan, 1.0
        out.road_code[k] = -1.0
