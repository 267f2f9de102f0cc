"""The pair metrics' per-step geometry in one compiled pass (SCTModel.pair_metrics).

For the logged vehicle–pedestrian pairs of a step: the vehicles' poses at their current speed
along their routes, the pedestrians' constant-velocity tracks, the gap now, and which pairs
can come near enough to touch within the horizon (for the TTC shapes, and for the SCT shapes
under every speed hypothesis). The operations are those of SCTModel.vehicle_poses,
contact.contact_gap and the near-pairs bound (tests/sct_reference.near_pairs) per scalar, in
the same order, with headings entering as the cosine / sine numpy computed (per path segment,
per pedestrian), so the values are the numpy code's bit for bit (tests/test_sct_vectorised.py
and test_sct_contact_kernel.py).

Frames and units: network coordinates in metres, speeds m/s, times s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from hiyari.risk.sct.contact_kernel import segment_at


@njit(cache=True)
def pair_screen(
    veh_speed: np.ndarray,
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
    ped_xy: np.ndarray,
    ped_dir: np.ndarray,
    ped_speed: np.ndarray,
    vslot: np.ndarray,
    pslot: np.ndarray,
    half_x: np.ndarray,
    half_y: np.ndarray,
    radius: float,
    reach2: np.ndarray,
    tracks: np.ndarray,
    track_slot: np.ndarray,
    track_reach2: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Vehicles of the path table (rows 0 .. V-1, speeds ``veh_speed`` (V,), arc lengths
    ``s0``) at ``times`` (K,): centres (V, K, 2), heading cos / sin (V, K). Pedestrians
    (``ped_xy`` (P, 2), unit heading ``ped_dir`` (P, 2), ``ped_speed`` (P,)): constant
    velocity tracks (P, K, 2). Pairs (vehicle ``vslot``, pedestrian ``pslot``) (n,): the gap
    now (m) between the rectangle grown to half sizes ``half_x`` / ``half_y`` (V,) and the
    disc of ``radius`` m; whether the track comes within sqrt(``reach2``) (V,) of the centre
    at some sample; and whether some speed hypothesis track of ``tracks`` (P', H, K, 2),
    pedestrian ``track_slot`` (n,), comes within sqrt(``track_reach2``) (V,) (all False when
    ``tracks`` holds no pedestrian)."""
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
    n_p = len(ped_xy)
    cv = np.empty((n_p, k_count, 2))
    for p in range(n_p):
        vx = ped_dir[p, 0] * ped_speed[p]
        vy = ped_dir[p, 1] * ped_speed[p]
        for k in range(k_count):
            cv[p, k, 0] = ped_xy[p, 0] + vx * times[k]
            cv[p, k, 1] = ped_xy[p, 1] + vy * times[k]
    n = len(vslot)
    gap = np.empty(n)
    near = np.zeros(n, np.bool_)
    near_track = np.zeros(n, np.bool_)
    n_h = tracks.shape[1]
    for i in range(n):
        a, p = vslot[i], pslot[i]
        dx = cv[p, 0, 0] - xy[a, 0, 0]
        dy = cv[p, 0, 1] - xy[a, 0, 1]
        x = dx * c[a, 0] + dy * sn[a, 0]
        y = -dx * sn[a, 0] + dy * c[a, 0]
        gap[i] = math.hypot(max(abs(x) - half_x[a], 0.0), max(abs(y) - half_y[a], 0.0)) - radius
        near[i] = _near(cv[p], xy[a], reach2[a])
        if len(tracks):
            for h in range(n_h):
                if _near(tracks[track_slot[i], h], xy[a], track_reach2[a]):
                    near_track[i] = True
                    break
    return xy, c, sn, cv, gap, near, near_track


@njit(cache=True)
def _near(points: np.ndarray, centre: np.ndarray, reach2: float) -> bool:
    """Whether ``points`` (K, 2) come within sqrt(``reach2``) of ``centre`` (K, 2) at some
    sample (tests/sct_reference.near_pairs for one pair)."""
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
