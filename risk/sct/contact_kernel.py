"""First contact of vehicle–pedestrian track pairs in one compiled loop.

The SCT metrics and the SCT controller ask, for many (vehicle pose track, pedestrian track)
pairs, when the pedestrian disc first touches the grown vehicle rectangle:
hiyari.risk.metrics.contact.contact_gap at every sample, +inf where the pedestrian is
protected (off the carriageway), then first_contact_time. In numpy that is a dozen passes
over (pairs, samples) arrays per call, on every evaluated step; here each pair is walked
sample by sample and stops at its first contact. The operations are those of contact_gap
(hiyari.kinematics.rectangle_point_distance: unrotate, clamp, hypot) and first_contact_time,
written out per scalar in the same order, so the times are numpy's bit for bit
(tests/unit/risk/test_sct_contact_kernel.py).

Frames and units: network coordinates in metres, headings as their cosine / sine, times s.
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.jit import njit


@njit(cache=True)
def _first_contacts(
    vxy: np.ndarray,
    vcos: np.ndarray,
    vsin: np.ndarray,
    half_x: np.ndarray,
    half_y: np.ndarray,
    radius: float,
    tracks: np.ndarray,
    exposed: np.ndarray,
    a_idx: np.ndarray,
    t_idx: np.ndarray,
    times: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    n = len(a_idx)
    first = np.full(n, np.inf)
    apart = np.zeros(n, np.bool_)
    for i in range(n):
        a = a_idx[i]
        first[i], apart[i] = _first_contact(
            vxy, vcos, vsin, a, half_x[a], half_y[a], radius, tracks, exposed, t_idx[i], times
        )
    return first, apart


@njit(cache=True)
def _first_contact(
    vxy: np.ndarray,
    vcos: np.ndarray,
    vsin: np.ndarray,
    a: int,
    hx: float,
    hy: float,
    radius: float,
    tracks: np.ndarray,
    exposed: np.ndarray,
    t: int,
    times: np.ndarray,
) -> tuple[float, bool]:
    """first_contacts of one pair: vehicle track ``a`` (half sizes ``hx``, ``hy`` m) and
    pedestrian track ``t``."""
    g0 = np.inf
    apart = False
    for k in range(len(times)):
        if exposed[t, k]:
            dx = tracks[t, k, 0] - vxy[a, k, 0]
            dy = tracks[t, k, 1] - vxy[a, k, 1]
            c, s = vcos[a, k], vsin[a, k]
            x = dx * c + dy * s
            y = -dx * s + dy * c
            lx = abs(x) - hx
            ly = abs(y) - hy
            g = math.hypot(max(lx, 0.0), max(ly, 0.0)) - radius
        else:
            g = np.inf
        if k == 0:
            apart = g > 0.0
        if g <= 0.0:
            if k == 0:
                return times[0] + (times[0] - times[0]) * 0.0, apart
            # an infinite gap before (a protected position): contact starts at the sample
            frac = g0 / (g0 - g) if math.isfinite(g0) else 1.0
            frac = min(max(frac, 0.0), 1.0)
            return times[k - 1] + (times[k] - times[k - 1]) * frac, apart
        g0 = g
    return np.inf, apart


def first_contacts(
    vxy: np.ndarray,
    vheading: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    margin: float,
    radius: float,
    tracks: np.ndarray,
    exposed: np.ndarray,
    a_idx: np.ndarray,
    t_idx: np.ndarray,
    times: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """First contact time (s, inf: none within ``times``) and whether the pair is apart at
    the first sample (gap > 0, a protected pedestrian counts as apart), each (n,), of pairs
    (vehicle track ``a_idx[i]``, pedestrian track ``t_idx[i]``).

    Vehicle tracks: rectangle centres ``vxy`` (A, K, 2) m, headings (A, K) rad, ``length`` /
    ``width`` (A,) m grown by ``margin`` m on every side; pedestrian tracks: disc centres
    ``tracks`` (T, K, 2) m of radius ``radius`` m, ``exposed`` (T, K) bool (False: the
    position is protected, no contact there); samples at ``times`` (K,) s. Equal to
    contact_gap, np.where(exposed, gap, inf) and first_contact_time on each pair."""
    half_x = 0.5 * np.asarray(length, float) + margin
    half_y = 0.5 * np.asarray(width, float) + margin
    return _first_contacts(
        np.ascontiguousarray(vxy, float),
        np.cos(vheading),
        np.sin(vheading),
        half_x,
        half_y,
        float(radius),
        np.ascontiguousarray(tracks, float),
        np.ascontiguousarray(exposed, np.bool_),
        np.asarray(a_idx, np.int64),
        np.asarray(t_idx, np.int64),
        np.asarray(times, float),
    )


@njit(cache=True)
def segment_at(cum: np.ndarray, count: int, first: int, s: float) -> int:
    """Table row of the segment of a path (arc lengths ``cum`` padded with +inf, ``count``
    segments from row ``first``) that arc length ``s`` m falls on; the end segments continue
    straight beyond either end."""
    below = 0  # the path's arc lengths at or before s: searchsorted(side="right")
    for c in cum:
        if s >= c:
            below += 1
    return min(max(below - 1, 0), count - 1) + first


@njit(cache=True)
def _path_at(
    cum: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    unit: np.ndarray,
    cum_start: np.ndarray,
    heading: np.ndarray,
    vehicles: np.ndarray,
    s: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    n, m = s.shape
    xy = np.empty((n, m, 2))
    hd = np.empty((n, m))
    for i in range(n):
        v = vehicles[i]
        for j in range(m):
            sj = s[i, j]
            k = segment_at(cum[v], count[v], first[v], sj)
            d = sj - cum_start[k]
            xy[i, j, 0] = start[k, 0] + unit[k, 0] * d
            xy[i, j, 1] = start[k, 1] + unit[k, 1] * d
            hd[i, j] = heading[k]
    return xy, hd


def path_at(
    cum: np.ndarray,
    count: np.ndarray,
    first: np.ndarray,
    start: np.ndarray,
    unit: np.ndarray,
    cum_start: np.ndarray,
    heading: np.ndarray,
    vehicles: np.ndarray,
    s: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(xy (n, ..., 2) m, heading (n, ...) rad) at arc lengths ``s`` (n, ...) m along the
    paths of ``vehicles`` (n,) in a table of concatenated path segments (see
    hiyari.risk.sct.model.PathTable: padded arc lengths ``cum`` (V, M), segment counts and
    first rows (V,), segment starts, unit directions, start arc lengths and headings); beyond
    either end the end segment is continued straight. PathTable.at's operations per scalar."""
    flat = np.ascontiguousarray(s, float).reshape(len(vehicles), -1)
    xy, hd = _path_at(
        cum, count, first, start, unit, cum_start, heading, np.asarray(vehicles, np.int64), flat
    )
    return xy.reshape(*s.shape, 2), hd.reshape(s.shape)


@njit(cache=True)
def travel_rows(
    accel: np.ndarray, v0: np.ndarray, v_max: np.ndarray, dt: float, stop_speed: float
) -> tuple[np.ndarray, np.ndarray]:
    """Speeds and distances (n, K) of acceleration profiles ``accel`` (n, K) m/s^2 from
    speeds ``v0`` (n,) m/s within 0 .. ``v_max`` (n,) m/s, sampled every ``dt`` s, braking
    profiles stopping below ``stop_speed``: hiyari.bridge.loop.drivers.sct_controller.travel per row."""
    n, k_count = accel.shape
    v = np.empty((n, k_count))
    s = np.empty((n, k_count))
    for i in range(n):
        # speeds: v0 plus the running sum of trapezoidal speed changes, clipped to 0 .. v_max
        v[i, 0] = min(max(v0[i] + 0.0, 0.0), v_max[i])
        c = 0.0
        for k in range(1, k_count):
            dv = 0.5 * (accel[i, k] + accel[i, k - 1]) * dt
            c = dv if k == 1 else c + dv
            v[i, k] = min(max(v0[i] + c, 0.0), v_max[i])
        if stop_speed > 0 and accel[i, k_count - 1] <= 0:
            stopped = False
            for k in range(k_count):
                stopped = stopped or v[i, k] < stop_speed
                if stopped:
                    v[i, k] = 0.0
        s[i, 0] = 0.0
        for k in range(1, k_count):
            ds = 0.5 * (v[i, k] + v[i, k - 1]) * dt
            s[i, k] = ds if k == 1 else s[i, k - 1] + ds
    return v, s


@njit(cache=True)
def project_rows(
    xy: np.ndarray,
    first: np.ndarray,
    count: np.ndarray,
    start: np.ndarray,
    vector: np.ndarray,
    length2: np.ndarray,
    cum_start: np.ndarray,
) -> np.ndarray:
    """(V,) arc length (m) of the point of each vehicle's path (segments ``first[v]`` ..
    ``first[v] + count[v] - 1`` of a PathTable: starts, vectors, squared lengths, start arc
    lengths) nearest to ``xy`` (V, 2) m; the first segment at the least distance.
    PathTable.project's operations per scalar."""
    out = np.empty(len(first))
    for v in range(len(first)):
        low, best, best_f = np.inf, first[v], 0.0
        for k in range(first[v], first[v] + count[v]):
            px = xy[v, 0] - start[k, 0]
            py = xy[v, 1] - start[k, 1]
            f = (px * vector[k, 0] + py * vector[k, 1]) / length2[k]
            f = min(max(f, 0.0), 1.0)
            dx = start[k, 0] + f * vector[k, 0] - xy[v, 0]
            dy = start[k, 1] + f * vector[k, 1] - xy[v, 1]
            d = math.sqrt(dx * dx + dy * dy)
            if d < low or k == first[v]:
                low, best, best_f = d, k, f
        out[v] = cum_start[best] + best_f * math.sqrt(length2[best])
    return out


@njit(cache=True)
def pair_time_bounds(
    vxy: np.ndarray,
    pxy: np.ndarray,
    reach: np.ndarray,
    radius: float,
    speed: np.ndarray,
    ped_speed: float,
    accel: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(V, P) lower bounds (s) on when vehicles (centres ``vxy`` (V, 2) m, circumscribed
    ``reach`` (V,) m, speeds (V,) m/s) and pedestrians (``pxy`` (P, 2) m, disc ``radius`` m,
    at most ``ped_speed`` m/s) could touch: at their current speeds, and with the vehicle
    accelerating at ``accel`` m/s^2 (hiyari.bridge.studies.sct.study's bound, per scalar)."""
    n_v, n_p = len(vxy), len(pxy)
    tau_now = np.empty((n_v, n_p))
    tau_acc = np.empty((n_v, n_p))
    for i in range(n_v):
        closing = speed[i] + ped_speed
        for j in range(n_p):
            dx = vxy[i, 0] - pxy[j, 0]
            dy = vxy[i, 1] - pxy[j, 1]
            gap = max(math.sqrt(dx * dx + dy * dy) - reach[i] - radius, 0.0)
            tau_now[i, j] = gap / closing
            tau_acc[i, j] = 2.0 * gap / (closing + math.sqrt(closing * closing + 2.0 * accel * gap))
    return tau_now, tau_acc


@njit(cache=True)
def within_reach(
    vxy: np.ndarray,
    pxy: np.ndarray,
    reach: np.ndarray,
    radius: float,
    speed: np.ndarray,
    ped_speed: np.ndarray,
    horizon: float,
    accel_travel: float,
) -> np.ndarray:
    """(V,) bool: vehicles (centres ``vxy`` (V, 2) m, circumscribed ``reach`` (V,) m, speeds
    (V,) m/s) that could touch some pedestrian (``pxy`` (P, 2) m, disc ``radius`` m, speeds
    ``ped_speed`` (P,) m/s) within ``horizon`` s, the vehicle gaining at most
    ``accel_travel`` m by accelerating (SCTController._within_reach, per scalar)."""
    out = np.zeros(len(vxy), np.bool_)
    for i in range(len(vxy)):
        for j in range(len(pxy)):
            dx = vxy[i, 0] - pxy[j, 0]
            dy = vxy[i, 1] - pxy[j, 1]
            gap = math.sqrt(dx * dx + dy * dy) - reach[i] - radius
            if gap <= (speed[i] + ped_speed[j]) * horizon + accel_travel:
                out[i] = True
                break
    return out


@njit(cache=True)
def within_reach_rows(
    xyz: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    speed: np.ndarray,
    veh_rows: np.ndarray,
    ped_rows: np.ndarray,
    ped_velocity: np.ndarray,
    margin: float,
    radius: float,
    fastest: float,
    horizon: float,
    accel_travel: float,
) -> np.ndarray:
    """within_reach of the vehicles ``veh_rows`` (V,) and pedestrians ``ped_rows`` (P,) of a
    state's columns (``xyz`` (N, 3) m, sizes (N,) m, ``speed`` (N,) m/s): each vehicle's
    circumscribed reach is 0.5 hypot(length, width) + ``margin`` m, each pedestrian moves at
    most |``ped_velocity``| (P, 2) m/s times ``fastest`` (SCTController._within_reach)."""
    n_v, n_p = len(veh_rows), len(ped_rows)
    vxy = np.empty((n_v, 2))
    reach = np.empty(n_v)
    v_speed = np.empty(n_v)
    for i in range(n_v):
        r = veh_rows[i]
        vxy[i, 0], vxy[i, 1] = xyz[r, 0], xyz[r, 1]
        reach[i] = 0.5 * math.hypot(length[r], width[r]) + margin
        v_speed[i] = speed[r]
    pxy = np.empty((n_p, 2))
    p_speed = np.empty(n_p)
    for j in range(n_p):
        r = ped_rows[j]
        pxy[j, 0], pxy[j, 1] = xyz[r, 0], xyz[r, 1]
        vx, vy = ped_velocity[j, 0], ped_velocity[j, 1]
        p_speed[j] = math.sqrt(vx * vx + vy * vy) * fastest  # numpy's norm: sqrt of the sum
    return within_reach(vxy, pxy, reach, radius, v_speed, p_speed, horizon, accel_travel)
