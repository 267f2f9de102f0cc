"""The pair metrics of one step in one compiled pass (SCTModel.pair_metrics).

For the logged vehicle–pedestrian pairs of a step: the vehicles' poses at their current speed
along their routes, the gap now, which pairs can come near enough to touch within the horizon
(for the TTC shapes, and for the SCT shapes under every speed hypothesis), and for those their
time to contact (the pedestrian's constant-velocity track) and SCT (the earliest contact over
the speed hypotheses' tracks). The operations are those of SCTModel.vehicle_poses,
contact.contact_gap, the near-pairs bound (tests/support/sct_reference.near_pairs) and
contact_kernel's first contacts per scalar, in the same order, with headings entering as the
cosine / sine numpy computed (per path segment, per pedestrian), so the values are the numpy
code's bit for bit (tests/e2e/studies/test_sct_vectorised.py and test_sct_contact_kernel.py).

Frames and units: network coordinates in metres, speeds m/s, times s.
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.jit import njit
from hiyari.risk.sct.contact_kernel import _first_contact, segment_at


@njit(cache=True)
def pair_pass(
    veh_speed: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    s0: np.ndarray,
    cum: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    unit: np.ndarray,
    cum_start: np.ndarray,
    seg_cos: np.ndarray,
    seg_sin: np.ndarray,
    times: np.ndarray,
    cv: np.ndarray,
    cv_exposed: np.ndarray,
    road: bool,
    vslot: np.ndarray,
    pslot: np.ndarray,
    ttc_margin: float,
    ttc_radius: float,
    sct_margin: float,
    sct_radius: float,
    tracks: np.ndarray,
    exposed: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time to contact (s), SCT (s) and the gap now (m) of pairs (vehicle ``vslot``,
    pedestrian ``pslot``) (n,), inf where they cannot touch within the horizon.

    Vehicles of the path table (rows 0 .. V-1, speeds ``veh_speed`` (V,) m/s, sizes (V,) m,
    arc lengths ``s0``) at their speed along their paths at ``times`` (K,). Pedestrians:
    constant-velocity tracks ``cv`` (P, K, 2) m with their carriageway flags ``cv_exposed``
    (P, K); speed-hypothesis ``tracks`` (P, H, K, 2) with ``exposed`` (P, H, K) (no SCT when
    they hold no pedestrian). Shapes: the vehicle rectangle grown by ``*_margin`` m, the
    pedestrian disc of ``*_radius`` m (TTC and gap: ttc; SCT: sct). With ``road``, the gap of
    a pedestrian off the carriageway now is inf."""
    n_v, k_count = len(s0), len(times)
    xy = np.empty((n_v, k_count, 2))
    c = np.empty((n_v, k_count))
    sn = np.empty((n_v, k_count))
    for v in range(n_v):
        for k in range(k_count):
            sj = s0[v] + veh_speed[v] * times[k]
            j = segment_at(cum[v], count[v], first[v], sj)
            d = sj - cum_start[j]
            xy[v, k, 0] = start[j, 0] + unit[j, 0] * d
            xy[v, k, 1] = start[j, 1] + unit[j, 1] * d
            c[v, k] = seg_cos[j]
            sn[v, k] = seg_sin[j]
    # each shape's half sizes and near-test reach (circumscribed circle, disc and slack)
    ttc_x, ttc_y, ttc_reach2 = _grown(length, width, ttc_margin, ttc_radius)
    sct_x, sct_y, sct_reach2 = _grown(length, width, sct_margin, sct_radius)
    n = len(vslot)
    ttc = np.full(n, np.inf)
    sct = np.full(n, np.inf)
    gap = np.empty(n)
    n_h = tracks.shape[1]
    for i in range(n):
        a, p = vslot[i], pslot[i]
        dx = cv[p, 0, 0] - xy[a, 0, 0]
        dy = cv[p, 0, 1] - xy[a, 0, 1]
        x = dx * c[a, 0] + dy * sn[a, 0]
        y = -dx * sn[a, 0] + dy * c[a, 0]
        g = math.hypot(max(abs(x) - ttc_x[a], 0.0), max(abs(y) - ttc_y[a], 0.0)) - ttc_radius
        gap[i] = g if cv_exposed[p, 0] or not road else np.inf
        if _near(cv[p], xy[a], ttc_reach2[a]):
            ttc[i], _ = _first_contact(
                xy, c, sn, a, ttc_x[a], ttc_y[a], ttc_radius, cv, cv_exposed, p, times
            )
        if len(tracks) == 0:
            continue
        near = False
        for h in range(n_h):
            if _near(tracks[p, h], xy[a], sct_reach2[a]):
                near = True
                break
        if near:
            for h in range(n_h):
                t, _ = _first_contact(
                    xy, c, sn, a, sct_x[a], sct_y[a], sct_radius, tracks[p], exposed[p], h, times
                )
                sct[i] = min(sct[i], t)
    return ttc, sct, gap


@njit(cache=True)
def _grown(
    length: np.ndarray, width: np.ndarray, margin: float, radius: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Half length and width (m) of vehicle rectangles grown by ``margin`` m, and the squared
    reach of the near test (circumscribed circle, a disc of ``radius`` m and slack), as
    contact_gap and the near-pairs bound compute them."""
    half_x = 0.5 * length + margin
    half_y = 0.5 * width + margin
    reach2 = np.empty(len(length))
    for v in range(len(length)):
        r = math.hypot(half_x[v], half_y[v]) + radius + 1e-6
        reach2[v] = r * r
    return half_x, half_y, reach2


@njit(cache=True)
def _near(points: np.ndarray, centre: np.ndarray, reach2: float) -> bool:
    """Whether ``points`` (K, 2) come within sqrt(``reach2``) of ``centre`` (K, 2) at some
    sample (tests/support/sct_reference.near_pairs for one pair)."""
    low = np.inf
    for k in range(len(points)):
        dx = points[k, 0] - centre[k, 0]
        dy = points[k, 1] - centre[k, 1]
        d2 = dx * dx + dy * dy
        if d2 != d2:  # as numpy's min: a NaN distance makes the minimum NaN
            low = d2
            break
        low = min(low, d2)
    return low <= reach2


@njit(cache=True, error_model="numpy")
def crossing_zones(
    vslot: np.ndarray,
    s_vehicle: np.ndarray,
    veh_length: np.ndarray,
    veh_width: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    vector: np.ndarray,
    cum_start: np.ndarray,
    ped_xy: np.ndarray,
    direction: np.ndarray,
    centre: np.ndarray,
    half_length: np.ndarray,
    ped_radius: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """hiyari.risk.metrics.contact.crossing_conflict per pair, its operations per scalar:
    pairs (n,) of a vehicle (path-table row ``vslot``, arc length ``s_vehicle`` m, size m)
    and a pedestrian at ``ped_xy`` (n, 2) on a crossing (``direction`` (n, 2), ``centre``
    (n, 2), ``half_length`` (n,) m). Returns (has_zone, vehicle_in, pedestrian_in) (n,)."""
    n = len(vslot)
    has = np.zeros(n, np.bool_)
    veh_in = np.zeros(n, np.bool_)
    ped_in = np.zeros(n, np.bool_)
    for i in range(n):
        v = vslot[i]
        u0, u1 = direction[i, 0], direction[i, 1]
        for m in range(first[v], first[v] + count[v]):
            d0, d1 = vector[m, 0], vector[m, 1]
            ap0 = start[m, 0] - ped_xy[i, 0]
            ap1 = start[m, 1] - ped_xy[i, 1]
            det = -u0 * d1 + u1 * d0
            lam = (-ap0 * d1 + ap1 * d0) / det
            mu = (u0 * ap1 - u1 * ap0) / det
            x0 = ped_xy[i, 0] + lam * u0
            x1 = ped_xy[i, 1] + lam * u1
            along = (x0 - centre[i, 0]) * u0 + (x1 - centre[i, 1]) * u1
            if abs(det) > 1e-9 and mu >= 0 and mu <= 1 and abs(along) <= half_length[i]:
                seg_len = math.sqrt(d0 * d0 + d1 * d1)
                s_x = cum_start[m] + mu * seg_len
                sin = max(abs(det) / max(seg_len, 1e-12), 0.3)  # near-parallel: capped
                cot = math.sqrt(max(1.0 - sin * sin, 0.0)) / sin
                reach = 0.5 * veh_length[i] + ped_radius / sin + 0.5 * veh_width[i] * cot
                has[i] = True
                veh_in[i] = abs(s_vehicle[i] - s_x) <= reach
                ped_in[i] = abs(lam) <= (0.5 * veh_width[i] + ped_radius) / sin
                break
    return has, veh_in, ped_in


@njit(cache=True)
def crossing_pairs(
    vi: np.ndarray,
    pj: np.ndarray,
    veh_slot: np.ndarray,
    ped_slot: np.ndarray,
    ped_crossing: np.ndarray,
    s0: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    xyz: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    vector: np.ndarray,
    cum_start: np.ndarray,
    direction: np.ndarray,
    centre: np.ndarray,
    half_length: np.ndarray,
    ped_radius: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """crossing_zones of pairs (vehicle rows ``vi``, pedestrian rows ``pj``) (n,) of a
    state's columns (sizes m, ``xyz`` (N, 3) m): each vehicle's path-table row
    (``veh_slot``) and arc length (``s0`` of the table rows), each pedestrian's crossing
    (``ped_crossing`` of its ``ped_slot``, -1: on none, no zone) as rectangles (C,) along
    ``direction``. Returns (has_zone, vehicle_in, pedestrian_in) (n,)."""
    n = len(vi)
    on = np.empty(n, np.int64)
    m = 0
    for i in range(n):
        if ped_crossing[ped_slot[pj[i]]] >= 0:
            on[m] = i
            m += 1
    on = on[:m]
    rows, peds = vi[on], pj[on]
    k = ped_crossing[ped_slot[peds]]
    slot = veh_slot[rows]
    ped_xy = np.empty((m, 2))
    for i in range(m):
        ped_xy[i, 0], ped_xy[i, 1] = xyz[peds[i], 0], xyz[peds[i], 1]
    zone, v_in, p_in = crossing_zones(
        slot, s0[slot], length[rows], width[rows], count, first, start, vector, cum_start,
        ped_xy, direction[k], centre[k], half_length[k], ped_radius,
    )  # fmt: skip
    has = np.zeros(n, np.bool_)
    veh_in = np.zeros(n, np.bool_)
    ped_in = np.zeros(n, np.bool_)
    has[on], veh_in[on], ped_in[on] = zone, v_in, p_in
    return has, veh_in, ped_in
