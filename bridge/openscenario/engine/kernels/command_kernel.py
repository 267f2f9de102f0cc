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
from hiyari.jit import njit
from hiyari.net.road.lane_profile import section_of


@njit(cache=True)
def command_rows(
    rows: np.ndarray,
    st: np.ndarray,
    cx: np.ndarray,
    cy: np.ndarray,
    length: np.ndarray,
    sent_speed: np.ndarray,
    centres: np.ndarray,
    heading: np.ndarray,
    send: np.ndarray,
    sumo: np.ndarray,
) -> None:
    """For table ``rows`` (``st``: the ActorTable's state matrix), into the last four arrays:
    box centres (m, 2) = reference point + (``cx``, ``cy``) in the vehicle frame, headings
    (m,), speeds to send (m,): the speed along the motion, NaN when equal to ``sent_speed``,
    which is updated; and what SUMO is told (3, m): the front-bumper point x, y (the centre
    plus half the ``length`` along the heading, as ``kinematics.point_ahead``) and the SUMO
    angle (degrees clockwise from north, as ``traffic.commands.heading_to_sumo_angle``)."""
    for i in range(len(rows)):
        k = rows[i]
        h, v, v_lat = st[H, k], st[V, k], st[V_LAT, k]
        c, s = math.cos(h), math.sin(h)
        centres[i, 0] = (cx[k] * c - cy[k] * s) + st[X, k]
        centres[i, 1] = (cx[k] * s + cy[k] * c) + st[Y, k]
        heading[i] = h
        half = 0.5 * length[k]
        sumo[0, i] = centres[i, 0] + half * c
        sumo[1, i] = centres[i, 1] + half * s
        sumo[2, i] = _remainder(90.0 - h * (180.0 / math.pi), 360.0)
        # the speed is along the path (motion_kernel): a lateral motion adds to it only when
        # it alone is faster (the actor then moves sideways)
        speed = abs(v) if v_lat == 0.0 else max(abs(v), abs(v_lat))
        send[i] = np.nan if speed == sent_speed[k] else speed
        sent_speed[k] = speed


@njit(cache=True)
def lane_keys(
    rows: np.ndarray,
    free: np.ndarray,
    road_code: np.ndarray,
    lane: np.ndarray,
    s: np.ndarray,
    sec_first: np.ndarray,
    sec_count: np.ndarray,
    sec_s0: np.ndarray,
    key: np.ndarray,
) -> np.ndarray:
    """Rows of ``rows`` whose (road code, lane, lane section index on the road; -1 off the
    roads) differs from ``key`` (E, 3), which is updated: their SUMO lane is to be looked up
    again. ``sec_*``: the lane sections of the LaneProfile of the table's roads."""
    changed = np.empty(len(rows), dtype=np.intp)
    n = 0
    for i in range(len(rows)):
        k = rows[i]
        rc = road_code[k]
        sec = -1
        if not free[k] and rc >= 0:
            sec = section_of(sec_s0, sec_first[rc], sec_count[rc], s[k]) - sec_first[rc]
        if key[k, 0] != rc or key[k, 1] != lane[k] or key[k, 2] != sec:
            key[k, 0], key[k, 1], key[k, 2] = rc, lane[k], sec
            changed[n] = k
            n += 1
    return changed[:n]


@njit(cache=True)
def command_step(
    rows: np.ndarray,
    st: np.ndarray,
    cx: np.ndarray,
    cy: np.ndarray,
    length: np.ndarray,
    sent_speed: np.ndarray,
    centres: np.ndarray,
    heading: np.ndarray,
    send: np.ndarray,
    sumo: np.ndarray,
    free: np.ndarray,
    road_code: np.ndarray,
    lane: np.ndarray,
    sec_first: np.ndarray,
    sec_count: np.ndarray,
    sec_s0: np.ndarray,
    key: np.ndarray,
) -> np.ndarray:
    """:func:`command_rows` and :func:`lane_keys` (the rows' s from ``st``) in one call:
    returns the rows whose SUMO lane is to be looked up again."""
    command_rows(rows, st, cx, cy, length, sent_speed, centres, heading, send, sumo)
    return lane_keys(rows, free, road_code, lane, st[S], sec_first, sec_count, sec_s0, key)


@njit(cache=True)
def advance_and_command(
    rows: np.ndarray,
    now: float,
    dt: float,
    kappa: np.ndarray,
    direction: np.ndarray,
    st: np.ndarray,
    has_long: np.ndarray,
    long_par: np.ndarray,
    long_done: np.ndarray,
    has_lat: np.ndarray,
    lat_par: np.ndarray,
    lat_done: np.ndarray,
    lateral: bool,
    rec_s0: np.ndarray,
    rec_c: np.ndarray,
    off_first: np.ndarray,
    off_count: np.ndarray,
    sec_first: np.ndarray,
    sec_count: np.ndarray,
    sec_s0: np.ndarray,
    w_first: np.ndarray,
    w_count: np.ndarray,
    max_lane: int,
    length: float,
    geom: np.ndarray,
    elev_s0: np.ndarray,
    elev_c: np.ndarray,
    c_rows: np.ndarray,
    c_st: np.ndarray,
    cx: np.ndarray,
    cy: np.ndarray,
    box_length: np.ndarray,
    sent_speed: np.ndarray,
    centres: np.ndarray,
    heading: np.ndarray,
    send: np.ndarray,
    sumo: np.ndarray,
    free: np.ndarray,
    road_code: np.ndarray,
    lane: np.ndarray,
    c_sec_first: np.ndarray,
    c_sec_count: np.ndarray,
    c_sec_s0: np.ndarray,
    key: np.ndarray,
) -> tuple[int, int, int, bool, np.ndarray]:
    """``motion_kernel.advance_and_place`` (its arguments first) and, when it ended no
    transition and placed every row (nothing for the storyboard to end in between), then
    :func:`command_step` (its arguments after, ``c_``: its own) in the same call. Returns
    advance_and_place's result and command_step's (empty when it did not run, as an ended
    transition or ``placed`` False tell: the caller ends them first, then commands)."""
    n_long, missing, n_lat, placed = advance_and_place(
        rows, now, dt, kappa, direction, st, has_long, long_par, long_done, has_lat, lat_par,
        lat_done, lateral, rec_s0, rec_c, off_first, off_count, sec_first, sec_count, sec_s0,
        w_first, w_count, max_lane, length, geom, elev_s0, elev_c,
    )  # fmt: skip
    if n_long > 0 or not placed:
        return n_long, missing, n_lat, placed, np.empty(0, dtype=np.intp)
    changed = command_step(
        c_rows, c_st, cx, cy, box_length, sent_speed, centres, heading, send, sumo, free,
        road_code, lane, c_sec_first, c_sec_count, c_sec_s0, key,
    )  # fmt: skip
    return n_long, missing, n_lat, placed, changed
