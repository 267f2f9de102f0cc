"""The batched SCT model and controller give exactly the per-vehicle results.

The reference below is the per-vehicle planner and the per-pair metric as they were before
they were batched (each vehicle's Path sampled on its own, contact.safety_cushion_time per
pair); the batched code must reproduce them bit for bit on many random scenes around a real
intersection, so the incident study's results do not depend on how steps are batched.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from hiyari.net.sumo.build import IntersectionParams, build_intersection
from hiyari.risk.metrics.contact import (
    ContactGeometry,
    contact_gap,
    first_contact_time,
    pedestrian_tracks,
    safety_cushion_time,
    unprotected,
)
from hiyari.risk.metrics.pedestrian_geometry import NetGeometry
from hiyari.risk.sct.controller import SCTController, ramp_profiles, travel
from hiyari.risk.sct.model import SCTModel, StepView
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState

ARMS = ("n", "e", "s", "w")


def reference_poses(view: StepView, row: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    k = view.veh_slot[row]
    return view.paths[k].at(view.s0[k] + s)


def reference_decide(
    ctrl: SCTController, view: StepView, row: int, v_max: float, a_free: float, engaged: bool
) -> float | None:
    """The SCT driver's plan for one vehicle, as planned one vehicle at a time."""
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
    road = model.carriageway
    protected = ~shapely.contains_xy(road, ped[..., 0], ped[..., 1])
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
    w = np.array([width])
    blocks = ctrl._stops_on_crossing(
        xy[None, :, -1], hd[None, :, -1], v[None, :, -1], np.array([length]), w
    )[0]
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


def reference_pair_metrics(model: SCTModel, view: StepView, vi: np.ndarray, pj: np.ndarray):
    state = view.state
    t = model.times
    poses = [reference_poses(view, int(r), state.speed[r] * t) for r in vi]
    vxy, vh = np.stack([p[0] for p in poses]), np.stack([p[1] for p in poses])
    length, width = state.length[vi], state.width[vi]
    cv = (
        np.stack([np.cos(state.heading[pj]), np.sin(state.heading[pj])], -1) * state.speed[pj, None]
    )
    ped_cv = state.xyz[pj, None, :2] + cv[:, None, :] * t[None, :, None]
    gap = contact_gap(vxy, vh, length[:, None], width[:, None], ped_cv, ContactGeometry())
    gap = unprotected(gap, ped_cv, model.carriageway)
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
    return first_contact_time(gap, t), sct, gap[:, 0]


@pytest.fixture(scope="module")
def geometry(tmp_path_factory):
    net = build_intersection(tmp_path_factory.mktemp("vec") / "x.net.xml", IntersectionParams())
    return NetGeometry.from_net(net)


def random_scene(rng: np.random.Generator, geometry: NetGeometry, model: SCTModel) -> WorldState:
    """Vehicles on random routes near the junction, pedestrians on kerbs and crossings."""
    nv, npd = int(rng.integers(1, 5)), int(rng.integers(1, 7))
    centre = geometry.junction_xy[0]
    ids, xy, heading = [], [], []
    for k in range(nv):
        a, b = rng.choice(len(ARMS), 2, replace=False)
        vid = f"veh{k}"
        model.set_route(vid, (f"{ARMS[a]}_in", f"{ARMS[b]}_out"))
        path = model._paths[vid]
        s = rng.uniform(0.7, 1.0) * np.linalg.norm(path.points[0] - centre)  # up to the centre
        p, h = path.at(np.array(s))
        ids.append(vid)
        xy.append(p + rng.normal(0.0, 0.2, 2))
        heading.append(float(h) + rng.normal(0.0, 0.02))
    lanes = sorted(geometry.footway_lanes) + list(geometry.crossings.lanes)
    ped_lane = []
    for k in range(npd):
        c = int(rng.integers(len(geometry.crossings)))
        along = rng.uniform(-1.3, 1.3) * geometry.crossings.half_length[c]
        xy.append(geometry.crossings.centre[c] + along * geometry.crossings.direction[c])
        heading.append(rng.uniform(-np.pi, np.pi))
        ids.append(f"ped{k}")
        ped_lane.append(lanes[int(rng.integers(len(lanes)))])
    n = nv + npd
    cls = np.array([ActorClass.CAR] * nv + [ActorClass.PEDESTRIAN] * npd, np.int8)
    speed = np.concatenate(
        [rng.uniform(0, 14, nv) * (rng.random(nv) > 0.2), rng.uniform(0, 2, npd)]
    )
    accel = np.concatenate([rng.uniform(-3, 2, nv), np.zeros(npd)])
    size = np.concatenate([np.full(nv, 4.5), np.full(npd, 0.5)])
    xyz = np.column_stack([np.array(xy), np.zeros(n)])
    lane = np.array([""] * nv + ped_lane, dtype=object)
    return WorldState(
        0.0,
        np.array(ids, object),
        cls,
        xyz,
        np.array(heading),
        speed,
        accel,
        size,
        size * 0.4,
        size,
        lane,
        lane.copy(),
    )


def test_batched_controller_and_metrics_match_the_per_vehicle_reference(geometry):
    rng = np.random.default_rng(7)
    model = SCTModel(geometry)
    ctrl = SCTController(model)
    commands = planned = finite_sct = pairs = 0
    for _ in range(300):
        state = random_scene(rng, geometry, model)
        view = model.prepare(state, rng.random(len(geometry.crossings)) > 0.3)
        rows = view.veh_rows
        v_max = rng.uniform(8, 14, len(rows))
        a_free = rng.uniform(1.5, 3.0, len(rows))
        engaged = rng.random(len(rows)) > 0.5
        got = ctrl.decide(view, rows, v_max, a_free, engaged)
        for k, r in enumerate(rows.tolist()):
            want = reference_decide(ctrl, view, r, v_max[k], a_free[k], bool(engaged[k]))
            if want is None:
                assert np.isnan(got[k])
            else:
                assert got[k] == want  # bit for bit
                commands += 1
            planned += 1
        vi, pj = np.meshgrid(rows, view.ped_rows, indexing="ij")
        vi, pj = vi.ravel(), pj.ravel()
        want = reference_pair_metrics(model, view, vi, pj)
        got_metrics = model.pair_metrics(view, vi, pj)
        for a, b in zip(got_metrics, want, strict=True):
            assert np.array_equal(a, b)
        finite_sct += int(np.isfinite(want[1]).sum())
        pairs += len(vi)
    # the scenes exercise the planner, not only its early exits
    assert commands > 0.2 * planned and finite_sct > 0.2 * pairs
