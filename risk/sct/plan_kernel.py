"""The SCT controller's per-step planning passes, compiled (SCTController.decide's array work).

decide asks, per step: where would each vehicle be under its own driver at full acceleration
(travel, then path sampling), which pedestrians come within ``act_distance`` of that track,
which vehicles may touch one of their pedestrian tracks (the near test), their first contacts
(first_contacts), and, for the vehicles that must plan, the SCT of every candidate profile.
In numpy that is some forty small array operations per step; here it is three calls. Each pass
runs the compiled kernels of contact_kernel (travel_rows, _first_contacts, the path sampling)
on the same operands in the same order, and headings enter as the cosine / sine numpy computed
per path segment, so the results are numpy's bit for bit
(tests/e2e/studies/test_sct_vectorised.py compares decide against the per-vehicle reference).

Frames and units: network coordinates in metres, speeds m/s, accelerations m/s^2, times s.
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.jit import njit
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


@njit(cache=True)
def _ramps(a0: np.ndarray, targets: np.ndarray, times: np.ndarray, jerk: float) -> np.ndarray:
    """the cubic ramps per scalar (tests/support/sct_reference.py ramp_profiles is the numpy oracle): (W, C, K) m/s^2."""
    out = np.empty((len(a0), len(targets), len(times)))
    for w in range(len(a0)):
        for c in range(len(targets)):
            delta = targets[c] - a0[w]
            ramp = max(3.0 * abs(delta) / jerk, 1e-6)
            for k in range(len(times)):
                tau = min(times[k] / ramp, 1.0)
                out[w, c, k] = targets[c] - delta * (1.0 - tau) ** 3.0
    return out


@njit(cache=True)
def _pick(sct: np.ndarray, targets: np.ndarray, order: np.ndarray, sct_safe: float) -> np.ndarray:
    """SCTController._pick per vehicle: the first candidate in ``order`` (mildest first) with
    no contact, else the first with SCT >= ``sct_safe``, else the hardest braking among the
    largest SCT."""
    n_w, n_c = sct.shape
    out = np.empty(n_w, np.int64)
    for w in range(n_w):
        pick = -1
        for c in order:
            if np.isinf(sct[w, c]):
                pick = c
                break
        if pick < 0:
            for c in order:
                if sct[w, c] >= sct_safe:
                    pick = c
                    break
        if pick < 0:
            best = sct[w].max()
            low = np.inf
            for c in range(n_c):
                if sct[w, c] == best and targets[c] < low:
                    low, pick = targets[c], c
            pick = max(pick, 0)  # all-NaN SCT: argmin of all-inf targets is 0
        out[w] = pick
    return out


@njit(cache=True)
def decide_speeds(
    v0: np.ndarray,
    a0: np.ndarray,
    v_max: np.ndarray,
    a_free: np.ndarray,
    engaged: np.ndarray,
    slot: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    reach2: np.ndarray,
    half_x: np.ndarray,
    half_y: np.ndarray,
    radius: float,
    s0: np.ndarray,
    cum: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    unit: np.ndarray,
    cum_start: np.ndarray,
    seg_cos: np.ndarray,
    seg_sin: np.ndarray,
    ped_now: np.ndarray,
    tracks: np.ndarray,
    exposed: np.ndarray,
    times: np.ndarray,
    act2: float,
    upto: int,
    sct_safe: float,
    targets: np.ndarray,
    order: np.ndarray,
    jerk: float,
    stop_speed: float,
    veh_reach: np.ndarray,
    area_reach: np.ndarray,
    area_centre: np.ndarray,
    area_corners: np.ndarray,
) -> np.ndarray:
    """SCTController.decide's planning for V vehicles in one pass: (V,) speeds (m/s) for the
    next step, NaN where the vehicle is left to its own driver. The steps and operands of
    free_screen, free_contacts, ramp_profiles, candidate_cushions, stops_on_crossing and _pick,
    in that order (see SCTController.decide); pedestrians' tracks (P, H, K, 2) with their
    carriageway flags (P, H, K)."""
    dt = times[1] - times[0]
    out = np.full(len(v0), np.nan)
    xy, vcos, vsin, near, may = free_screen(
        v0, v_max, a_free, dt, s0, slot, cum, count, first, start, unit, cum_start,
        seg_cos, seg_sin, ped_now, act2, tracks, reach2, upto, engaged,
    )  # fmt: skip
    keep = np.flatnonzero(may)
    if len(keep) == 0:
        return out
    n_p, n_h, k_count = tracks.shape[0], tracks.shape[1], tracks.shape[2]
    slots = np.array([p for p in range(n_p) if near[:, p].any()], np.int64)
    ped = np.empty((len(slots) * n_h, k_count, 2))
    ped_exposed = np.empty((len(slots) * n_h, k_count), np.bool_)
    for i in range(len(slots)):
        ped[i * n_h : (i + 1) * n_h] = tracks[slots[i]]
        ped_exposed[i * n_h : (i + 1) * n_h] = exposed[slots[i]]
    mine = np.empty((len(keep), len(slots) * n_h), np.bool_)
    for a in range(len(keep)):
        for i in range(len(slots)):
            mine[a, i * n_h : (i + 1) * n_h] = near[keep[a], slots[i]]
    hx, hy = half_x[keep], half_y[keep]
    plan, apart = free_contacts(
        xy[keep], vcos[keep], vsin[keep], hx, hy, radius, ped, ped_exposed, mine, times,
        sct_safe, engaged[keep],
    )  # fmt: skip
    w = np.flatnonzero(plan)
    if len(w) == 0:
        return out
    k = keep[w]
    accel = _ramps(a0[k], targets, times, jerk)
    v, end_xy, end_seg, sct = candidate_cushions(
        accel, v0[k], v_max[k], dt, stop_speed, s0, slot[k], cum, count, first, start, unit,
        cum_start, seg_cos, seg_sin, hx[w], hy[w], radius, ped, ped_exposed, apart[w], times,
    )  # fmt: skip
    n_c = len(targets)
    v_end = v[:, :, k_count - 1].copy()
    if len(area_centre) and (v_end <= 0.0).any():
        end_cos = np.empty((len(w), n_c))
        end_sin = np.empty((len(w), n_c))
        for a in range(len(w)):
            for c in range(n_c):
                end_cos[a, c] = seg_cos[end_seg[a, c]]
                end_sin[a, c] = seg_sin[end_seg[a, c]]
        blocks = stops_on_crossing(
            end_xy, end_cos, end_sin, v_end, length[k], width[k], veh_reach[k], area_reach,
            area_centre, area_corners,
        )  # fmt: skip
        # keep crossings clear: never plan to stop on one (unless every plan does)
        for a in range(len(w)):
            if not blocks[a].all():
                for c in range(n_c):
                    if blocks[a, c]:
                        sct[a, c] = -1.0
    pick = _pick(sct, targets, order, sct_safe)
    for a in range(len(w)):
        out[k[a]] = v[a, pick[a], 1]
    return out


@njit(cache=True)
def decide_rows(
    rows: np.ndarray,
    speed: np.ndarray,
    accel: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    xyz: np.ndarray,
    v_max: np.ndarray,
    a_free: np.ndarray,
    engaged: np.ndarray,
    veh_slot: np.ndarray,
    ped_rows: np.ndarray,
    margin: float,
    radius: float,
    s0: np.ndarray,
    cum: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    unit: np.ndarray,
    cum_start: np.ndarray,
    seg_cos: np.ndarray,
    seg_sin: np.ndarray,
    tracks: np.ndarray,
    exposed: np.ndarray,
    times: np.ndarray,
    act2: float,
    upto: int,
    sct_safe: float,
    targets: np.ndarray,
    order: np.ndarray,
    jerk: float,
    stop_speed: float,
    area_reach: np.ndarray,
    area_centre: np.ndarray,
    area_corners: np.ndarray,
) -> np.ndarray:
    """decide_speeds for vehicle rows ``rows`` (V,) of a state's columns (speeds m/s,
    accelerations m/s^2, sizes m, ``xyz`` (N, 3) m) and its pedestrian rows ``ped_rows``:
    the vehicles' shapes are their rectangles grown by ``margin`` m, the pedestrians' discs of
    ``radius`` m (the near test's reach: circumscribed circle, disc and slack), each vehicle's
    allowed speed at least its own (SCTController.decide's arrays, built here)."""
    v0 = speed[rows]
    length_v, width_v = length[rows], width[rows]
    half_x, half_y = 0.5 * length_v + margin, 0.5 * width_v + margin
    reach2 = np.empty(len(rows))
    veh_reach = np.empty(len(rows))
    for i in range(len(rows)):
        reach = math.hypot(half_x[i], half_y[i]) + radius + 1e-6
        reach2[i] = reach * reach
        veh_reach[i] = 0.5 * math.hypot(length_v[i], width_v[i])
    ped_now = np.empty((len(ped_rows), 2))
    for j in range(len(ped_rows)):
        ped_now[j, 0], ped_now[j, 1] = xyz[ped_rows[j], 0], xyz[ped_rows[j], 1]
    return decide_speeds(
        v0, accel[rows], np.maximum(v_max, v0), a_free, engaged, veh_slot[rows], length_v,
        width_v, reach2, half_x, half_y, radius, s0, cum, count, first, start, unit, cum_start,
        seg_cos, seg_sin, ped_now, tracks, exposed, times, act2, upto, sct_safe, targets, order,
        jerk, stop_speed, veh_reach, area_reach, area_centre, area_corners,
    )  # fmt: skip
