"""The SCT planner and pair metrics as they were before they were batched: one vehicle at a
time, each vehicle's Path projected and sampled on its own, contact.safety_cushion_time per
pair. Tests compare the batched code against these, bit for bit."""

from __future__ import annotations

import numpy as np
import shapely

from hiyari.bridge.loop.drivers.sct_controller import SCTController, travel
from hiyari.jit import njit
from hiyari.risk.metrics.contact import (
    ContactGeometry,
    contact_gap,
    first_contact_time,
    pedestrian_tracks,
    safety_cushion_time,
    unprotected,
)
from hiyari.risk.sct.model import SCTModel, StepView


def ramp_profiles(
    a0: float | np.ndarray, targets: np.ndarray, times: np.ndarray, jerk_limit: float
) -> np.ndarray:
    """(..., C, K) acceleration, m/s^2, of cubic ramps from ``a0`` (a float, or (...) one per
    vehicle) to each target at ``times`` s: a(t) = aT - (aT - a0) (1 - t / T)^3 up to T, then
    aT. The jerk is largest at the start, 3 |aT - a0| / T, and T is chosen to make that the
    jerk limit; it fades to 0 at the plateau. (Re-planned every step, a ramp that started with
    zero jerk would never leave a0.)"""
    delta = targets - np.asarray(a0, float)[..., None]
    ramp = np.maximum(3.0 * np.abs(delta) / jerk_limit, 1e-6)
    tau = np.minimum(times / ramp[..., None], 1.0)
    return targets[:, None] - delta[..., None] * (1.0 - tau) ** 3


def reference_poses(view: StepView, row: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Poses of vehicle ``row`` at arc lengths ``s`` travelled from its projection."""
    path = view.paths[view.veh_slot[row]]
    return path.at(path.project(view.state.xyz[row, :2]) + s)


def reference_decide(
    ctrl: SCTController, view: StepView, row: int, v_max: float, a_free: float, engaged: bool
) -> float | None:
    """The SCT driver's plan for one vehicle, planned alone."""
    cfg, model = ctrl.config, ctrl.model
    state = view.state
    times = model.times
    dt = float(times[1] - times[0])
    v0, a0 = float(state.speed[row]), float(state.accel[row])
    v_max = max(v_max, v0)
    _, s_free = travel(np.full((1, len(times)), a_free), v0, v_max, dt)
    xy, hd = reference_poses(view, row, s_free)
    now = state.xyz[view.ped_rows, :2]
    d = now[:, None, :] - xy[0, ::5][None]
    keep = np.einsum("pkj,pkj->pk", d, d).min(axis=1) <= cfg.act_distance**2
    if not keep.any():
        return None
    slots = np.flatnonzero(keep)
    ped = pedestrian_tracks(now[slots], view.ped_velocity[slots], model.config.speed_factors, times)
    ped = ped.reshape(-1, len(times), 2)
    protected = ~shapely.contains_xy(model.carriageway, ped[..., 0], ped[..., 1])
    length, width = state.length[row], state.width[row]
    contact = model.config.contact
    gap = contact_gap(xy[:, None], hd[:, None], length, width, ped[None], contact)
    gap = np.where(protected[None], np.inf, gap)
    apart = gap[0, :, 0] > 0
    if not apart.any():
        return None
    sct_free = first_contact_time(gap[:, apart], times).min()
    if np.isinf(sct_free) or (sct_free >= cfg.sct_safe and not engaged):
        return None
    accel = ramp_profiles(a0, ctrl._targets, times, cfg.jerk_limit)
    v, s = travel(accel, v0, v_max, dt, cfg.stop_speed)
    xy, hd = reference_poses(view, row, s)
    gap = contact_gap(xy[:, None], hd[:, None], length, width, ped[apart][None], contact)
    gap = np.where(protected[apart][None], np.inf, gap)
    sct = first_contact_time(gap, times).min(axis=1)
    blocks = _stops_on_crossing(model, xy[:, -1], hd[:, -1], v[:, -1], length, width)
    if not blocks.all():
        sct = np.where(blocks, -1.0, sct)
    ordered = sct[ctrl._order]
    clear = np.flatnonzero(np.isinf(ordered))
    ok = clear if len(clear) else np.flatnonzero(ordered >= cfg.sct_safe)
    if len(ok):
        pick = ctrl._order[ok[0]]
    else:
        best = np.flatnonzero(sct == sct.max())
        pick = best[np.argmin(ctrl._targets[best])]
    return float(v[pick, 1])


def _stops_on_crossing(
    model: SCTModel,
    xy: np.ndarray,
    heading: np.ndarray,
    v_end: np.ndarray,
    length: float,
    width: float,
) -> np.ndarray:
    from hiyari.kinematics import footprint_corners, overlap_depth

    areas = model.geometry.crossings
    stopped = v_end <= 0.0
    if len(areas) == 0 or not stopped.any():
        return np.zeros(len(xy), bool)
    rect = footprint_corners(xy, heading, length, width)
    n, a = len(rect), len(areas)
    depth = overlap_depth(np.repeat(rect, a, 0), np.tile(areas.corners, (n, 1, 1)))
    return stopped & (depth.reshape(n, a) > 0).any(axis=1)


def reference_pair_metrics(
    model: SCTModel,
    view: StepView,
    vi: np.ndarray,
    pj: np.ndarray,
    ttc_contact: ContactGeometry | None = None,
    with_sct: bool = True,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """TTC, SCT and gap now of pairs (``vi``, ``pj``), pair by pair."""
    state = view.state
    t = model.times
    if len(vi) == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    poses = [reference_poses(view, int(r), state.speed[r] * t) for r in vi]
    vxy, vh = np.stack([p[0] for p in poses]), np.stack([p[1] for p in poses])
    length, width = state.length[vi], state.width[vi]
    u = np.stack([np.cos(state.heading[pj]), np.sin(state.heading[pj])], -1)
    ped_cv = state.xyz[pj, None, :2] + (u * state.speed[pj, None])[:, None, :] * t[None, :, None]
    contact = ttc_contact or ContactGeometry()
    gap = contact_gap(vxy, vh, length[:, None], width[:, None], ped_cv, contact)
    gap = unprotected(gap, ped_cv, model.carriageway)
    ttc = first_contact_time(gap, t)
    if not with_sct:
        return ttc, np.full(len(vi), np.inf), gap[:, 0]
    slot = view.ped_slot[pj]
    sct = safety_cushion_time(
        vxy,
        vh,
        length,
        width,
        state.xyz[pj, :2],
        view.ped_velocity[slot],
        model.config,
        model.carriageway,
    )
    return ttc, sct, gap[:, 0]


@njit(cache=True)
def _near_pairs(
    centre: np.ndarray,
    reach2: np.ndarray,
    points: np.ndarray,
    a_idx: np.ndarray,
    t_idx: np.ndarray,
    upto: np.ndarray,
) -> np.ndarray:
    out = np.zeros(len(a_idx), np.bool_)
    for i in range(len(a_idx)):
        a, t = a_idx[i], t_idx[i]
        low = np.inf
        for k in range(upto[i]):
            dx = points[t, k, 0] - centre[a, k, 0]
            dy = points[t, k, 1] - centre[a, k, 1]
            d2 = dx * dx + dy * dy
            if d2 != d2:  # as numpy's min: a NaN distance makes the minimum NaN
                low = d2
                break
            low = min(low, d2)
        out[i] = low <= reach2[a]
    return out


def near_pairs(
    centre: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    margin: float,
    radius: float,
    points: np.ndarray,
    a_idx: np.ndarray,
    t_idx: np.ndarray,
    upto: np.ndarray | int | None = None,
) -> np.ndarray:
    """(n,) bool: whether pedestrian track ``t_idx[i]`` (``points`` (T, K, 2) m) comes within
    reach of vehicle track ``a_idx[i]`` (rectangle centres ``centre`` (A, K, 2) m, ``length``
    / ``width`` (A,) m grown by ``margin``, disc ``radius`` m) at some sample before
    ``upto`` (per pair, or one for all; None: every sample): the grown rectangle lies within
    its circumscribed circle, so contact needs the point within that circle plus the disc.
    False: no contact at those samples. A micrometre of slack keeps rounding from ever
    excluding a contact. The bound pair_kernel computes per pair (its _near, with the reach of
    its _grown), as it was computed for all pairs at once before it moved there."""
    reach = np.hypot(
        0.5 * np.asarray(length, float) + margin, 0.5 * np.asarray(width, float) + margin
    )
    reach = reach + radius + 1e-6
    n = len(a_idx)
    k = np.shape(centre)[1]
    upto = np.full(n, k if upto is None else upto, np.int64) if np.ndim(upto) == 0 else upto
    return _near_pairs(
        np.ascontiguousarray(centre, float),
        reach * reach,
        np.ascontiguousarray(points, float),
        np.asarray(a_idx, np.int64),
        np.asarray(t_idx, np.int64),
        np.asarray(upto, np.int64),
    )
