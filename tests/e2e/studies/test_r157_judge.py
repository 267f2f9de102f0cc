"""The UN R157 judge: Preventable points pass with perfect perception, not without sensors."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import pytest

from hiyari.bridge.studies.r157_judge import JudgeOptions, judge
from hiyari.bridge.studies.report.r157 import write_report
from hiyari.risk.cc.boundary import Grid
from hiyari.risk.cc.r157_points import R157Config, generate_points, write_points_csv


@pytest.fixture(scope="module")
def points():
    cfg = R157Config(
        ve0_kmh=Grid(40, 60, 20),
        dv_kmh=Grid(10, 40, 30),
        vy_fine=Grid(1.0, 2.0, 1.0),
        vy_coarse=Grid(1.0, 2.0, 1.0),
        gx_max_g=Grid(0.5, 1.0, 0.5),
    )
    return generate_points(cfg).points


def test_perfect_perception_passes_every_preventable_point(points, tmp_path):
    """Every Preventable cut-out point, and every Preventable cut-in point within 2 m of the
    C&C boundary (the hard ones: 10 m and 30 m beyond it the ego has more room, and
    test_judge_warm judges such a point), passes with perfect perception.
    The 4 decel points are judged with the same options by test_cli_judge below (through the
    command line), and the Unpreventable points have no verdict to check here: neither is run
    twice."""
    judged = [
        p
        for p in points
        if p.expected == "preventable"
        and (p.scenario == "cut-out" or (p.scenario == "cut-in" and not p.id.endswith("0m")))
    ]
    assert {p.scenario for p in judged} == {"cut-in", "cut-out"}
    assert {p.id.rsplit("/", 1)[1] for p in judged if p.scenario == "cut-in"} == {
        "boundary",
        "boundary+1m",
        "boundary+2m",
    }
    report = judge(judged, JudgeOptions(perception="perfect", workers=2), progress=False)
    s = report.summary()["perfect"]
    assert s["preventable"] == len(judged) >= 20
    why = {
        r["id"]: (r["verdict"], r["error"]) for r in report.rows if r["id"] in s["failed_points"]
    }
    assert s["verdict"] == "pass" and s["failed"] == 0, why
    paths = write_report(report, tmp_path)
    assert {p.name for p in paths} >= {"judge.csv", "summary.json", "judge_cut-in.png"}


def test_without_sensors_the_judge_fails(points, tmp_path):
    """Judged with and without perception: every point that fails without perception and
    passes with perfect perception is listed in differences.csv as never detected (its target
    was in sight from the start), and no other point is."""
    cut_in = [p for p in points if p.scenario == "cut-in" and p.expected == "preventable"][:6]
    report = judge(cut_in, JudgeOptions(perception="perfect,none", workers=2), progress=False)
    s = report.summary()["none"]
    assert s["verdict"] == "fail" and s["failed"] >= 3
    assert report.summary()["perfect"]["failed"] == 0
    write_report(report, tmp_path)
    with (tmp_path / "differences.csv").open() as f:
        listed = list(csv.DictReader(f))
    assert sorted(r["id"] for r in listed) == sorted(s["failed_points"])
    assert {(r["perfect"], r["verdict"], r["cause"]) for r in listed} == {
        ("pass", "fail", "not detected")
    }


def test_cli_judge(points, tmp_path):
    """The command line judges the grid's 4 (Preventable) decel points with perfect
    perception: all pass."""
    decel = [p for p in points if p.scenario == "decel"]
    assert len(decel) == 4 and all(p.expected == "preventable" for p in decel)
    f = write_points_csv(decel, tmp_path / "p.csv")
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "hiyari",
            "r157",
            "judge",
            str(f),
            "-o",
            str(tmp_path / "j"),
            "-q",
            "-j",
            "1",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert "PASS: 4/4 Preventable points passed" in proc.stdout
    assert json.loads((tmp_path / "j" / "summary.json").read_text())["perfect"]["verdict"] == "pass"
