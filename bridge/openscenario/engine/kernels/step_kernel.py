"""A quiet step of the storyboard in one compiled call: the snapshot and the triggers, then,
when no trigger fired, the scripted actors' motion and commands.

A step is quiet when the storyboard changed nothing at the previous update and no action can
end before the motion pass tells so (the executor checks this and keeps the arguments from
step to step: its arrays are updated in place). Python runs between the passes only when a
trigger fired or a transition ended: one call instead of two, with no Python in between.

numba's on-disk cache of this kernel holds the motion and command kernels compiled into it,
and is renewed only when this file changes: a change to those kernels must touch this file
(as the path-speed model of the motion kernel did), or a cached build keeps the old motion.
"""

from __future__ import annotations

import numpy as np

from hiyari.bridge.openscenario.engine.kernels.command_kernel import advance_and_command
from hiyari.bridge.openscenario.engine.kernels.trigger_kernel import gather_and_evaluate
from hiyari.jit import njit


@njit(cache=True)
def quiet_step(
    xyz: np.ndarray,
    w_heading: np.ndarray,
    w_speed: np.ndarray,
    w_accel: np.ndarray,
    now: float,
    step_no: int,
    t_next: float,
    rows: np.ndarray,
    centre_offset: np.ndarray,
    own: np.ndarray,
    road_code: np.ndarray,
    table: np.ndarray,
    direction: np.ndarray,
    present: np.ndarray,
    centre: np.ndarray,
    ref: np.ndarray,
    ent: np.ndarray,
    active: np.ndarray,
    cond: np.ndarray,
    time_value: np.ndarray,
    static: np.ndarray,
    group_start: np.ndarray,
    trigger_group: np.ndarray,
    prev: np.ndarray,
    history: np.ndarray,
    row_table: np.ndarray,
    row_value: np.ndarray,
    points: np.ndarray,
    since: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    on_net: np.ndarray,
    contact: np.ndarray,
    contact_any: np.ndarray,
    states: np.ndarray,
    transitions: np.ndarray,
    work: np.ndarray,
    counts: np.ndarray,
    flags: np.ndarray,
    fired: np.ndarray,
    m_rows: np.ndarray,
    dt: float,
    kappa: np.ndarray,
    m_direction: np.ndarray,
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
    road_length: float,
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
    c_road_code: np.ndarray,
    lane: np.ndarray,
    c_sec_first: np.ndarray,
    c_sec_count: np.ndarray,
    c_sec_s0: np.ndarray,
    key: np.ndarray,
) -> tuple[int, int, int, int, bool, np.ndarray]:
    """``trigger_kernel.gather_and_evaluate`` on the WorldState arrays (``xyz`` ...
    ``w_accel``) at scenario time ``now`` (s), evaluation ``step_no``; then, when no trigger
    fired, ``command_kernel.advance_and_command`` to ``t_next`` (s) (``m_``: the motion
    pass's own arguments, ``c_``: the command pass's). Returns (triggers fired, then
    advance_and_command's result; zeros, False and no rows when a trigger fired: the motion
    did not run)."""
    n_fired = gather_and_evaluate(
        rows, xyz, w_heading, w_speed, w_accel, centre_offset, own, road_code, table,
        direction, present, centre, ref, ent, now, step_no, active, cond, time_value, static,
        group_start, trigger_group, prev, history, row_table, row_value, points, since,
        length, width, on_net, contact, contact_any, states, transitions, work, counts,
        flags, fired,
    )  # fmt: skip
    if n_fired > 0:
        return n_fired, 0, -1, 0, False, np.empty(0, dtype=np.intp)
    n_long, missing, n_lat, placed, changed = advance_and_command(
        m_rows, t_next, dt, kappa, m_direction, st, has_long, long_par, long_done, has_lat,
        lat_par, lat_done, lateral, rec_s0, rec_c, off_first, off_count, sec_first,
        sec_count, sec_s0, w_first, w_count, max_lane, road_length, geom, elev_s0, elev_c,
        c_rows, c_st, cx, cy, box_length, sent_speed, centres, heading, send, sumo, free,
        c_road_code, lane, c_sec_first, c_sec_count, c_sec_s0, key,
    )  # fmt: skip
    return n_fired, n_long, missing, n_lat, placed, changed
