"""False-positive braking statistics against hand-computed series."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from hiyari.bridge.loop.result import RunResult
from hiyari.risk.metrics.false_braking import false_braking
from hiyari.risk.metrics.ground_truth import path_headway

INF = math.inf


def test_false_braking_by_hand():
    t = [0.1 * k for k in range(12)]
    accel = [0.0, -1.0, -1.2, 0.0, -0.4, -3.0, -8.0, -8.0, -8.0, 0.0, -2.0, -2.0]
    ttc = [INF, INF, INF, INF, INF, INF, INF, 0.9, INF, INF, INF, INF]
    aeb = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 7.85, 7.85, 7.85, 0.0, 2.0, 2.0]
    fb = false_braking(t, accel, ttc, aeb)
    # ACC: one episode over 0.1-0.3 s peaking at 1.2 with no hazard (-0.4 is below the
    # 0.5 m/s^2 floor)
    assert (fb["acc"].events, fb["acc"].peak_decel) == (1, 1.2)
    assert fb["acc"].duration == pytest.approx(0.2)
    # 0.5-0.9 s: ACC then AEB braking for a hazard that the truth shows at 0.7 s (started
    # early, held after): not false. 1.0-1.2 s: AEB braking with no hazard at all
    assert (fb["aeb"].events, fb["aeb"].peak_decel) == (1, 2.0)
    assert fb["aeb"].duration == pytest.approx(0.2)


def test_false_braking_in_the_result_fields():
    r = RunResult("x")
    for k, (a, ttc) in enumerate([(0.0, INF), (-1.0, INF), (-1.0, INF), (0.0, 2.0)]):
        s = r.series
        s.t.append(0.05 * k)
        s.ego_speed.append(10.0)
        s.ego_accel_cmd.append(a)
        s.gap.append(INF)
        s.ttc_true.append(ttc)
        s.ttc_stack.append(INF)
        s.aeb_stage.append(0)
        s.aeb_decel.append(0.0)
    d = r.as_dict()
    assert d["false_acc_brakings"] == 1 and d["false_acc_braking_s"] == 0.1
    assert d["false_acc_peak_decel_mps2"] == 1.0
    assert d["false_aeb_brakings"] == 0 and d["false_aeb_peak_decel_mps2"] == 0.0
    assert "false_acc_brakings" in r.row()


def test_following_braking_is_not_false_for_the_acc_only():
    """Two braking episodes with no finite TTC: one while a real actor is 1.5 s ahead in the
    path (following: not false for the ACC), one with the nearest 3.5 s ahead (false). The
    same series as AEB braking stays false: the AEB needs a finite TTC."""
    t = [0.1 * k for k in range(6)]
    accel = [-1.0, -1.0, 0.0, -2.0, -2.0, 0.0]
    ttc = [INF] * 6
    headway = [1.5, 1.6, 1.6, 3.5, 3.5, 3.5]
    fb = false_braking(t, accel, ttc, [0.0] * 6, headway=headway)
    assert (fb["acc"].events, fb["acc"].peak_decel) == (1, 2.0)
    assert fb["acc"].duration == pytest.approx(0.2)
    fb = false_braking(t, accel, ttc, [1.0, 1.0, 0.0, 2.0, 2.0, 0.0], headway=headway)
    assert fb["aeb"].events == 2 and fb["acc"].events == 0


def test_path_headway_by_hand():
    """Ego 4.8 x 1.9 m at the origin heading +x at 10 m/s. A 5 x 1.9 m car 30 m ahead in its
    lane: gap 30 - 2.4 - 2.5 = 25.1 m, headway 2.51 s. A car 20 m ahead in the left lane
    (side clearance 3.5 - 1.9 = 1.6 m) moving toward the ego at 1.5 m/s comes within 0.5 m in
    0.73 s < 1 s: in the path, gap 15.1 m, headway 1.51 s; moving away it is not."""
    vx, vy = 8.0, -1.5
    xy = np.array([[0.0, 0.0], [30.0, 0.0], [20.0, 3.5]])
    length, width = np.array([4.8, 5.0, 5.0]), np.full(3, 1.9)
    cut_in = np.array([0.0, 0.0, math.atan2(vy, vx)])
    speed = np.array([10.0, 10.0, math.hypot(vx, vy)])
    assert path_headway(xy, cut_in, speed, length, width, 0) == pytest.approx(1.51)
    away = np.array([0.0, 0.0, math.atan2(-vy, vx)])
    assert path_headway(xy, away, speed, length, width, 0) == pytest.approx(2.51)
    stopped = np.array([0.0, 10.0, 10.0])
    assert path_headway(xy, cut_in, stopped, length, width, 0) == INF


def test_alks_cut_in_braking_is_following_not_false(tmp_path):
    """UN R157 ALKS 4.4.1 (real SUMO, perfect perception): the car cuts in 23 m ahead at
    40 km/h while the ego drives 60 km/h. The ACC brakes while the car still moves sideways
    (its constant-velocity TTC is infinite: it is predicted to cross the ego's path), and
    that braking is not counted as false."""
    from openscenario_files import ALKS

    from hiyari.bridge.cli.main import main

    scenario = next(ALKS.glob("alks_scenario_4_4_1_*.xosc"))
    assert main(["run", str(scenario), "-o", str(tmp_path), "-q", "--no-record"]) == 0
    rows = list(csv.DictReader((tmp_path / "timeseries.csv").open()))
    braking = [r for r in rows if float(r["ego_accel_cmd"]) <= -0.5]
    assert braking and math.isinf(float(braking[0]["ttc_true"]))
    assert float(braking[0]["headway_true"]) < 2.0
    result = json.loads((tmp_path / "result.json").read_text())["result"]
    assert result["false_acc_brakings"] == 0 and result["false_aeb_brakings"] == 0
