"""The per-step command of the scripted actors in one compiled pass: the centre of each
actor's box (what SUMO is told to place), its heading and the speed to report, sent only when
it changed (SUMO holds the speed set last); and which actors' SUMO lane may have changed.

Frames and units: world x, y in metres, headings in radians from world +x, speeds m/s.
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.bridge.openscenario.engine.kernels.motion_kernel import (
    V_LAT,
    H,
    S,
    V,
    X,
    Y,
    _remainder,
    advance_and_place,
)
from hiyari.bridge.openscenario.engine.kernels.tables import (
    ActorArrays,
    CommandArrays,
    LaneArrays,
    RoadArrays,
)
from hiyari.jit import njit
from hiyari.net.road.lane_profile import section_of


@njit(cache=True)
def command_rows(cmd: CommandArrays, actors: ActorArrays) -> None:
    """For the rows ``cmd.rows`` of the ActorTable (``actors``), into ``cmd``'s last four
    arrays: box centres = reference point + (``cx``, ``cy``) in the vehicle frame, headings,
    speeds to send: the speed along the motion, NaN when equal to ``sent_speed``, which is
    updated; and what SUMO is told: the front-bumper point x, y (the centre plus half the
    ``length`` along the heading, as ``kinematics.point_ahead``) and the SUMO angle (degrees
    clockwise from north, as ``traffic.commands.heading_to_sumo_angle``)."""
    cmd, actors = CommandArrays(*cmd), ActorArrays(*actors)
    st, cx, cy, sent_speed = actors.state, cmd.cx, cmd.cy, cmd.sent_speed
    centres, sumo = cmd.centres, cmd.sumo
    rows = cmd.rows
    for i in range(len(rows)):
        k = rows[i]
        h, v, v_lat = st[H, k], st[V, k], st[V_LAT, k]
        c, s = math.cos(h), math.sin(h)
        centres[i, 0] = (cx[k] * c - cy[k] * s) + st[X, k]
        centres[i, 1] = (cx[k] * s + cy[k] * c) + st[Y, k]
        cmd.heading[i] = h
        half = 0.5 * cmd.length[k]
        sumo[0, i] = centres[i, 0] + half * c
        sumo[1, i] = centres[i, 1] + half * s
        sumo[2, i] = _remainder(90.0 - h * (180.0 / math.pi), 360.0)
        # the speed is along the path (motion_kernel): a lateral motion adds to it only when
        # it alone is faster (the actor then moves sideways)
        speed = abs(v) if v_lat == 0.0 else max(abs(v), abs(v_lat))
        cmd.send[i] = np.nan if speed == sent_speed[k] else speed
        sent_speed[k] = speed


@njit(cache=True)
def lane_keys(cmd: CommandArrays, actors: ActorArrays, lanes: LaneArrays) -> np.ndarray:
    """Rows of ``cmd.rows`` whose (road code, lane, lane section index on the road; -1 off
    the roads) differs from ``cmd.lane_key``, which is updated: their SUMO lane is to be
    looked up again. ``lanes``: the lane profile of the ActorTable's roads."""
    cmd, actors, lanes = CommandArrays(*cmd), ActorArrays(*actors), LaneArrays(*lanes)
    rows, key, s = cmd.rows, cmd.lane_key, actors.state[S]
    sec_first = lanes.sec_first
    changed = np.empty(len(rows), dtype=np.intp)
    n = 0
    for i in range(len(rows)):
        k = rows[i]
        rc = actors.road_code[k]
        sec = -1
        if not actors.free[k] and rc >= 0:
            sec = section_of(lanes.sec_s0, sec_first[rc], lanes.sec_count[rc], s[k])
            sec -= sec_first[rc]
        lane = actors.lane[k]
        if key[k, 0] != rc or key[k, 1] != lane or key[k, 2] != sec:
            key[k, 0], key[k, 1], key[k, 2] = rc, lane, sec
            changed[n] = k
            n += 1
    return changed[:n]


@njit(cache=True)
def command_step(cmd: CommandArrays, actors: ActorArrays, lanes: LaneArrays) -> np.ndarray:
    """:func:`command_rows` and :func:`lane_keys` in one call: returns the rows whose SUMO
    lane is to be looked up again."""
    command_rows(cmd, actors)
    return lane_keys(cmd, actors, lanes)


@njit(cache=True)
def advance_and_command(
    rows: np.ndarray,
    now: float,
    dt: float,
    lateral: bool,
    actors: ActorArrays,
    lanes: LaneArrays,
    road: RoadArrays,
    cmd: CommandArrays,
) -> tuple[int, int, int, bool, np.ndarray]:
    """``motion_kernel.advance_and_place`` (its arguments first) and, when it ended no
    transition and placed every row (nothing for the storyboard to end in between), then
    :func:`command_step` of ``cmd`` in the same call. Returns advance_and_place's result and
    command_step's (empty when it did not run, as an ended transition or ``placed`` False
    tell: the caller ends them first, then commands)."""
    n_long, missing, n_lat, placed = advance_and_place(rows, now, dt, lateral, actors, lanes, road)
    if n_long > 0 or not placed:
        return n_long, missing, n_lat, placed, np.empty(0, dtype=np.intp)
    return n_long, missing, n_lat, placed, command_step(cmd, actors, lanes)
