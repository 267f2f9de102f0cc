"""Untested runs never pass (issue 30, item 1): an ego that stops before the cut-in starts
has not been tested on it, and the judge counts the point as not tested, not passed."""

from __future__ import annotations

import pytest

from hiyari.bridge.studies.r157_judge import JudgeOptions, judge
from hiyari.risk.cc.boundary import Grid
from hiyari.risk.cc.r157_points import R157Config, generate_points


@pytest.fixture(scope="module")
def cut_in():
    cfg = R157Config(
        ve0_kmh=Grid(60, 60, 20),
        dv_kmh=Grid(20, 20, 30),
        vy_fine=Grid(1.0, 1.0, 1.0),
        vy_coarse=Grid(1.0, 1.0, 1.0),
        gx_max_g=Grid(0.5, 0.5, 0.5),
    )
    points = [p for p in generate_points(cfg).points if p.scenario == "cut-in"]
    return [next(p for p in points if p.expected == "preventable")]


def test_an_ego_stopped_before_the_cut_in_is_not_tested_and_not_passed(cut_in):
    options = JudgeOptions(
        perception="perfect", in_process=True, stack="phantom_stack:phantom_brake"
    )
    report = judge(cut_in, options, progress=False)
    (row,) = report.rows
    assert row["collision"] == "False"  # no collision: the old judge's pass
    assert row["verdict"] == "not tested"
    assert row["tested"] is False and row["untested_cause"].startswith("braked at")
    s = report.summary()["perfect"]
    assert s["passed"] == 0 and s["not_tested"] == 1 and s["preventable_not_tested"] == 1
    assert s["verdict"] == "not tested" and s["not_tested_points"] == [row["id"]]
    assert s["false_activations"] == 1  # the phantom: nothing in conflict


def test_the_same_point_with_hiyaris_stack_is_tested_and_passes(cut_in):
    report = judge(cut_in, JudgeOptions(perception="perfect", in_process=True), progress=False)
    (row,) = report.rows
    assert row["tested"] is True and row["verdict"] == "pass"
    s = report.summary()["perfect"]
    assert s["passed"] == 1 and s["not_tested"] == 0 and s["false_activations"] == 0
