"""False-positive braking statistics against hand-computed series."""

from __future__ import annotations

import math

import pytest

from hiyari.bridge.loop.result import RunResult
from hiyari.risk.metrics.false_braking import false_braking

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
