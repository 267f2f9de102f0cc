"""The SCT controller's per-step planning passes, compiled (SCTController.decide's array work).

decide asks, per step: where would each vehicle be under its own driver at full acceleration
(travel, then path sampling), which pedestrians come within ``act_distance`` of that track,
which vehicles may touch one of their pedestrian tracks (near_pairs), their first contacts
(first_contacts), and, for the vehicles that must plan, the SCT of every candidate profile.
In numpy that is some forty small array operations per step; here it is three calls. Each pass
runs the compiled kernels of contact_kernel (travel_rows, _first_contacts, the path sampling)
on the same operands in the same order, and headings enter as the cosine / sine numpy computed
per path segment, so the results are numpy's bit for bit
(tests/test_sct_vectorised.py compares decide against the per-vehicle reference).

Frames and units: network coordinates in metres, speeds m/s, accelerations m/s^2, times s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from hiyari.risk.sct.contact_kernel import _first_contacts, segment_at, travel_rows


@njit(cache=True)
def _sample(
    s0: np.ndarray,
    slot: np.ndarray,
    s: np.ndarray,
    cum: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    unit: np.ndarray,
    cum_start: np.ndarray,
    seg_cos: np.ndarray,
    seg_sin: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Centres (n, K, 2), segment rows (n, K), heading cos / sin (n, K) of the vehicles of
    path-table rows ``slot[i // (n // len(slot))]`` at arc lengths ``s0`` + ``s`` (n, K)."""
    n, k_count = s.shape
    per = n // len(slot)
    xy = np.empty((n, k_count, 2))
    seg = np.empty((n, k_count), np.int64)
    c = np.empty((n, k_count))
    sn = np.empty((n, k_count))
    for i in range(n):
        v = slot[i // per]
        base = s0[v]
        for j in range(k_count):
            sj = base + s[i, j]
            k = segment_at(cum[v], count[v], first[v], sj)
            d = sj - cum_start[k]
            xy[i, j, 0] = start[k, 0] + unit[k, 0] * d
            xy[i, j, 1] = start[k, 1] + unit[k, 1] * d
            seg[i, j] = k
            c[i, j] = seg_cos[k]
            sn[i, j] = seg_sin[k]
    return xy, seg, c, sn


@njit(cache=True)
def free_screen(
    v0: np.ndarray,
    v_max: np.ndarray,
    a_free: np.ndarray,
    dt: float,
    s0: np.ndarray,
    slot: np.ndarray,
    cum: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    unit: np.ndarray,
    cum_start: np.ndarray,
    seg_cos: np.ndarray,
    seg_sin: np.ndarray,
    ped_now: np.ndarray,
    act2: float,
    tracks: np.ndarray,
    reach2: np.ndarray,
    upto: int,
    engaged: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The vehicles under their own driver at full acceleration ``a_free`` (V,) from ``v0``
    to ``v_max`` (V,): centres (V, K, 2) and heading cos / sin (V, K) along their paths
    (path-table rows ``slot`` (V,), arc lengths ``s0`` per table row); ``near`` (V, P): the
    pedestrian (``ped_now`` (P, 2)) within sqrt(``act2``) of every fifth sample; ``may``
    (V,): some track (``tracks`` (P, H, K, 2)) of a near pedestrian comes within
    sqrt(``reach2``) of the centre before sample ``upto`` (every sample when ``engaged``)."""
    n_v, n_p, n_h, k_count = len(v0), tracks.shape[0], tracks.shape[1], tracks.shape[2]
    accel = np.empty((n_v, k_count))
    for v in range(n_v):
        accel[v, :] = a_free[v]
    _, s = travel_rows(accel, v0, v_max, dt, 0.0)
    xy, _, c, sn = _sample(s0, slot, s, cum, count, first, start, unit, cum_start, seg_cos, seg_sin)
    near = np.zeros((n_v, n_p), np.bool_)
    may = np.zeros(n_v, np.bool_)
    for v in range(n_v):
        for p in range(n_p):
            low = np.inf
            for k in range(0, k_count, 5):
                dx = ped_now[p, 0] - xy[v, k, 0]
                dy = ped_now[p, 1] - xy[v, k, 1]
                d2 = dx * dx + dy * dy
                if d2 != d2:  # as numpy's min: NaN wins
                    low = d2
                    break
                low = min(low, d2)
            near[v, p] = low <= act2
        last = k_count if engaged[v] else upto
        for p in range(n_p):
            if may[v]:
                break
            if not near[v, p]:
                continue
            for h in range(n_h):
                low = np.inf
                for k in range(last):
                    dx = tracks[p, h, k, 0] - xy[v, k, 0]
                    dy = tracks[p, h, k, 1] - xy[v, k, 1]
                    d2 = dx * dx + dy * dy
                    if d2 != d2:
                        low = d2
                        break
                    low = min(low, d2)
                if low <= reach2[v]:
                    may[v] = True
                    break
    return xy, c, sn, near, may


@njit(cache=True)
def free_contacts(
    xy: np.ndarray,
    vcos: np.ndarray,
    vsin: np.ndarray,
    half_x: np.ndarray,
    half_y: np.ndarray,
    radius: float,
    ped: np.ndarray,
    exposed: np.ndarray,
    mine: np.ndarray,
    times: np.ndarray,
    sct_safe: float,
    engaged: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """For vehicles (centres ``xy`` (V, K, 2), heading cos / sin (V, K), half sizes (V,) m
    with the margin) and their pedestrian tracks (``ped`` (T, K, 2), ``exposed`` (T, K),
    ``mine`` (V, T)): ``plan`` (V,) whether the vehicle must plan (apart from some track, and
    its first contact comes before ``sct_safe`` or it is ``engaged``) and ``apart`` (V, T)."""
    vi, ti = np.nonzero(mine)
    first, ok = _first_contacts(xy, vcos, vsin, half_x, half_y, radius, ped, exposed, vi, ti, times)
    n_v = len(xy)
    apart = np.zeros(mine.shape, np.bool_)
    sct = np.full(n_v, np.inf)
    for i in range(len(vi)):
        if ok[i]:
            apart[vi[i], ti[i]] = True
            sct[vi[i]] = min(sct[vi[i]], first[i])
    plan = np.zeros(n_v, np.bool_)
    for v in range(n_v):
        if np.isfinite(sct[v]) and (sct[v] < sct_safe or engaged[v]):
            plan[v] = apart[v].any()
    return plan, apart


@njit(cache=True)
def candidate_cushions(
    accel: np.ndarray,
    v0: np.ndarray,
    v_max: np.ndarray,
    dt: float,
    stop_speed: float,
    s0: np.ndarray,
    slot: np.ndarray,
    cum: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    unit: np.ndarray,
    cum_start: np.ndarray,
    seg_cos: np.ndarray,
    seg_sin: np.ndarray,
    half_x: np.ndarray,
    half_y: np.ndarray,
    radius: float,
    ped: np.ndarray,
    exposed: np.ndarray,
    apart: np.ndarray,
    times: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Candidate profiles ``accel`` (W, C, K) of W vehicles (speeds ``v0`` (W,) within
    ``v_max`` (W,), path-table rows ``slot`` (W,)): speeds (W, C, K), end centres (W, C, 2),
    end segment rows (W, C) and the SCT (W, C) s against the vehicle's ``apart`` (W, T)
    tracks (inf: no contact within the horizon)."""
    n_w, n_c, k_count = accel.shape
    v, s = travel_rows(
        accel.reshape(n_w * n_c, k_count),
        np.repeat(v0, n_c),
        np.repeat(v_max, n_c),
        dt,
        stop_speed,
    )
    xy, seg, c, sn = _sample(
        s0, slot, s, cum, count, first, start, unit, cum_start, seg_cos, seg_sin
    )
    wi, ti = np.nonzero(apart)
    a = np.empty(len(wi) * n_c, np.int64)
    t = np.empty(len(wi) * n_c, np.int64)
    for i in range(len(wi)):
        for k in range(n_c):
            a[i * n_c + k] = wi[i] * n_c + k
            t[i * n_c + k] = ti[i]
    first_t, _ = _first_contacts(
        xy, c, sn, np.repeat(half_x, n_c), np.repeat(half_y, n_c), radius, ped, exposed, a, t, times
    )
    sct = np.full(n_w * n_c, np.inf)
    for i in range(len(a)):
        sct[a[i]] = min(sct[a[i]], first_t[i])
    return (
        v.reshape(n_w, n_c, k_count),
        xy[:, -1].copy().reshape(n_w, n_c, 2),
        seg[:, -1].copy().reshape(n_w, n_c),
        sct.reshape(n_w, n_c),
    )


@njit(cache=True)
def stops_on_crossing(
    end_xy: np.ndarray,
    end_cos: np.ndarray,
    end_sin: np.ndarray,
    v_end: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    veh_reach: np.ndarray,
    area_reach: np.ndarray,
    centre: np.ndarray,
    corners: np.ndarray,
) -> np.ndarray:
    """(W, C) bool: candidates ending stopped (``v_end`` (W, C) <= 0) with the rectangle of
    vehicle w (``length`` / ``width`` (W,) m, centre ``end_xy`` (W, C, 2), heading cos / sin
    (W, C)) overlapping a crossing (``corners`` (A, 4, 2), counter-clockwise). Crossings
    farther than ``veh_reach`` (W,) + ``area_reach`` (A,) + 1 mm from the centre are not
    tested (bounding circles). hiyari.kinematics.footprint_corners and overlap_depth > 0,
    their operations per scalar."""
    n_w, n_c = v_end.shape
    blocks = np.zeros((n_w, n_c), np.bool_)
    rect = np.empty((4, 2))
    for w in range(n_w):
        hl, hw = 0.5 * length[w], 0.5 * width[w]
        for c in range(n_c):
            if not v_end[w, c] <= 0.0:
                continue
            x, y = end_xy[w, c, 0], end_xy[w, c, 1]
            co, si = end_cos[w, c], end_sin[w, c]
            # footprint_corners: rotate_xy of (hl, 0) and (0, hw)
            fx, fy = hl * co - 0.0 * si, hl * si + 0.0 * co
            lx, ly = 0.0 * co - hw * si, 0.0 * si + hw * co
            rect[0, 0], rect[0, 1] = x + fx + lx, y + fy + ly
            rect[1, 0], rect[1, 1] = x - fx + lx, y - fy + ly
            rect[2, 0], rect[2, 1] = x - fx - lx, y - fy - ly
            rect[3, 0], rect[3, 1] = x + fx - lx, y + fy - ly
            for a in range(len(centre)):
                dx, dy = x - centre[a, 0], y - centre[a, 1]
                if math.sqrt(dx * dx + dy * dy) <= veh_reach[w] + area_reach[a] + 1e-3:
                    if _overlap_depth(rect, corners[a]) > 0:
                        blocks[w, c] = True
                        break
    return blocks


@njit(cache=True)
def _overlap_depth(qa: np.ndarray, qb: np.ndarray) -> float:
    """hiyari.kinematics.overlap_depth of one pair of quadrilaterals (4, 2)."""
    depth = np.inf
    for axis in range(4):
        q = qa if axis < 2 else qb
        e = axis % 2
        ex = q[e + 1, 0] - q[e, 0]
        ey = q[e + 1, 1] - q[e, 1]
        norm = max(math.sqrt(ex * ex + ey * ey), 1e-12)
        ax, ay = ex / norm, ey / norm
        lo_a, hi_a, lo_b, hi_b = np.inf, -np.inf, np.inf, -np.inf
        for k in range(4):
            pa = qa[k, 0] * ax + qa[k, 1] * ay
            pb = qb[k, 0] * ax + qb[k, 1] * ay
            lo_a, hi_a = min(lo_a, pa), max(hi_a, pa)
            lo_b, hi_b = min(lo_b, pb), max(hi_b, pb)
        depth = min(depth, min(hi_a, hi_b) - max(lo_a, lo_b))
    return depth
