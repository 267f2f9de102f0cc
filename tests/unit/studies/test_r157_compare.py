"""Sensors against ground truth (hiyari.bridge.studies.r157_compare): each differing verdict gets
the perception limit its times and ranges point to; equal verdicts are not listed."""

from __future__ import annotations

import pytest

from hiyari.bridge.studies.r157_compare import differences, explain, rig_reach_m

REACH = 200.0


def _row(cond: str, verdict: str, **values: object) -> dict:
    row = {"id": "cut-in/p1", "scenario": "cut-in", "condition": cond, "verdict": verdict,
           "error": "", "untested_cause": "", "aeb_brake_time_s": "", "target_in_sight_s": "",
           "target_in_sight_range_m": "", "target_tracked_s": "", "target_tracked_range_m": ""}  # fmt: skip
    row.update({k: str(v) for k, v in values.items()})
    return row


PERFECT = _row("perfect", "pass", aeb_brake_time_s=2.0)


def _sensed(verdict: str = "fail", cond: str = "sensors/clear", **values: object) -> dict:
    base = dict(target_in_sight_s=0.0, target_in_sight_range_m=40.0, target_tracked_s=0.3,
                target_tracked_range_m=38.0)  # fmt: skip
    return _row(cond, verdict, **{**base, **values})


@pytest.mark.parametrize(
    "sensed, cause",
    [
        (_sensed("crashed", error="worker process died of SIGSEGV (signal 11)"), "run failed"),
        (_sensed("not tested", untested_cause="braked 6.1 m/s2 at 0.10 s"), "false activation"),
        (_sensed(cond="sensors/fog"), "disturbance preset"),
        # in sight only after perfect perception braked (2.0 s): hidden until then
        (_sensed(target_in_sight_s=2.5, target_tracked_s=2.7), "occlusion"),
        (_sensed(target_in_sight_s=""), "occlusion"),  # never in sight
        # tracked at 185 m >= 0.9 x 200 m: it was tracked as soon as it came within reach
        (_sensed(target_in_sight_range_m=250.0, target_tracked_range_m=185.0), "range"),
        (_sensed(target_tracked_s=2.4, target_tracked_range_m=20.0), "tracking latency"),
        (_sensed(target_tracked_s="", target_tracked_range_m=""), "not detected"),
    ],
)
def test_each_cause(sensed, cause):
    got, detail = explain(PERFECT, sensed, REACH)
    assert got == cause
    assert detail


def test_a_sensor_pass_where_truth_failed_is_listed_as_closed_loop():
    truth = _row("perfect", "fail", aeb_brake_time_s=2.0)
    assert explain(truth, _sensed("pass"), REACH)[0] == "closed loop"


def test_only_differing_verdicts_are_listed_per_condition():
    other = dict(PERFECT, id="cut-in/p2")
    rows = [PERFECT, other, _sensed("pass"), dict(_sensed("fail"), id="cut-in/p2")]
    diffs = differences(rows, REACH)
    assert [(d.id, d.perfect, d.verdict) for d in diffs] == [("cut-in/p2", "pass", "fail")]
    assert differences([r for r in rows if r["condition"] != "perfect"], REACH) == []


def test_the_default_rig_reaches_its_longest_sensor_range():
    assert rig_reach_m() == 200.0  # the camera's 200 m (LiDAR 120 m, radar 150 m)
