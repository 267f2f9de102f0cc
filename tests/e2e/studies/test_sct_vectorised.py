"""The batched SCT model and controller give exactly the per-vehicle results.

The reference (tests/support/sct_reference.py) is the per-vehicle planner and the per-pair metrics as
they were before they were batched; the batched code must reproduce them (to the last bits: the
oracle's numpy pow may take a SIMD path that libm's does not, tests/support/ulp.py), on many
random scenes around a real intersection and in a short SCT arm of the incident study on real
SUMO, so the study's results do not depend on how steps are batched.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import numpy as np
import pytest
from sct_reference import reference_decide, reference_pair_metrics
from ulp import assert_within_ulps

from hiyari.bridge.loop.drivers.sct_controller import SCTController
from hiyari.bridge.studies.sct.study import StudyConfig, build_inputs, run_arm
from hiyari.net.sumo.build import IntersectionParams, build_intersection
from hiyari.risk.metrics.incidents import write_encounters_csv
from hiyari.risk.metrics.pedestrian_geometry import NetGeometry
from hiyari.risk.sct.model import SCTModel, StepView
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.commands import Commands
from hiyari.traffic.world_state import WorldState

pytestmark = pytest.mark.timeout(180)

ARMS = ("n", "e", "s", "w")


@pytest.fixture(scope="module")
def geometry(tmp_path_factory: pytest.TempPathFactory) -> NetGeometry:
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


@pytest.mark.kernels
def test_batched_controller_and_metrics_match_the_per_vehicle_reference(
    geometry: NetGeometry,
) -> None:
    rng = np.random.default_rng(7)
    model = SCTModel(geometry)
    ctrl = SCTController(model)
    commands = planned = finite_sct = pairs = 0
    for _ in range(100):
        state = random_scene(rng, geometry, model)
        view = model.prepare(state, rng.random(len(geometry.crossings)) > 0.3)
        rows = view.veh_rows
        v_max = rng.uniform(8, 14, len(rows))
        a_free = rng.uniform(1.5, 3.0, len(rows))
        engaged = rng.random(len(rows)) > 0.5
        paths = [view.paths[view.veh_slot[r]] for r in rows]
        s0 = [p.project(state.xyz[r, :2]) for p, r in zip(paths, rows, strict=True)]
        assert view.s0.tolist() == s0
        got = ctrl.decide(view, rows, v_max, a_free, engaged)
        for k, r in enumerate(rows.tolist()):
            want = reference_decide(ctrl, view, r, v_max[k], a_free[k], bool(engaged[k]))
            if want is None:
                assert np.isnan(got[k])
            else:
                # the numpy oracle's pow may take a SIMD path; 64 ULP covers the integration
                assert_within_ulps(got[k], want, ulps=64, scale=1.0)
                commands += 1
            planned += 1
        vi, pj = np.meshgrid(rows, view.ped_rows, indexing="ij")
        vi, pj = vi.ravel(), pj.ravel()
        want = reference_pair_metrics(model, view, vi, pj)
        got_metrics = model.pair_metrics(view, vi, pj)
        for a, b in zip(got_metrics, want, strict=True):
            assert_within_ulps(a, b, ulps=64, scale=1.0)
        finite_sct += int(np.isfinite(want[1]).sum())
        pairs += len(vi)
    # the scenes exercise the planner, not only its early exits
    assert commands > 0.2 * planned and finite_sct > 0.2 * pairs


def short_sct_arm(folder: Path, reference: bool) -> tuple[bytes, list, int, np.ndarray]:
    """Three simulated minutes of the study's SCT arm: encounters CSV, every speed command and
    hand-back (time, vehicle, speed or None), the evaluated steps and the vehicles' travel
    times; with ``reference``, planned and measured by the per-vehicle reference."""
    commands: list[tuple[float, str, float | None]] = []
    set_speed, release = Commands.set_speed, Commands.release_speed

    def log_set(sim: Commands, vid: str, speed: float) -> None:
        commands.append((sim.time, vid, speed))
        set_speed(sim, vid, speed)

    def log_release(sim: Commands, vid: str) -> None:
        commands.append((sim.time, vid, None))
        release(sim, vid)

    def decide_each(
        ctrl: SCTController,
        view: StepView,
        rows: np.ndarray,
        v_max: np.ndarray,
        a_free: np.ndarray,
        engaged: np.ndarray,
    ) -> np.ndarray:
        plans = [
            reference_decide(ctrl, view, int(r), float(v), float(a), bool(e))
            for r, v, a, e in zip(rows, v_max, a_free, engaged, strict=True)
        ]
        return np.array([np.nan if p is None else p for p in plans])

    Commands.set_speed, Commands.release_speed = log_set, log_release
    if reference:
        SCTController.decide = decide_each
        SCTModel.pair_metrics = reference_pair_metrics
    config = StudyConfig(days=180 / 86400, runs=1, seed=3)
    task = next(t for t in build_inputs(config, folder) if t.arm == "sct")
    result = run_arm(task)
    csv = write_encounters_csv(folder / "encounters.csv", result.encounters).read_bytes()
    order = sorted(commands, key=lambda c: (c[0], c[1]))  # hand-backs come from a set
    return csv, order, result.evaluated_steps, result.travel_time


def test_short_sct_arm_is_the_per_vehicle_reference_run(tmp_path: Path) -> None:
    with ProcessPoolExecutor(2, mp_context=get_context("spawn")) as pool:
        batched = pool.submit(short_sct_arm, tmp_path / "batched", False)
        reference = pool.submit(short_sct_arm, tmp_path / "reference", True)
        csv, commands, evaluated, travel = batched.result()
        csv_ref, commands_ref, evaluated_ref, travel_ref = reference.result()
    assert sum(c[2] is not None for c in commands) > 50  # the controller was busy
    assert csv.count(b"\n") > 2  # and there were encounters to log
    assert commands == commands_ref
    assert csv == csv_ref
    assert evaluated == evaluated_ref
    assert np.array_equal(travel, travel_ref)
