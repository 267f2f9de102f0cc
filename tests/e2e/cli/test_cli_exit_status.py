"""Exit statuses (hiyari.bridge.cli.status): 0 when every verdict passed, 3 when the runs
completed and a verdict failed (distinct from 1, an error), on real runs read back."""

from __future__ import annotations

import csv
import json
from pathlib import Path

from hiyari.bridge.cli import status
from hiyari.bridge.cli.main import main

# the cut-in car lands 8 m ahead of an ego 40 km/h faster that does not see it: contact
COLLIDING_CUT_IN = """
[scenario]
type = "cut-in"
duration = 3
step_length = 0.05
[ego]
perception = "none"
[parameters]
ve0_kmh = 60
vo0_kmh = 20
dx0_m = 8
vy_ms = 2.0
"""


def test_statuses_are_distinct_and_the_shells():
    assert (status.OK, status.ERROR, status.VERDICT_FAIL, status.RUNS_CRASHED) == (0, 1, 3, 4)
    assert (status.INTERRUPTED, status.TERMINATED) == (128 + 2, 128 + 15)


def test_run_with_a_collision_exits_3(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    scen = tmp_path / "collide.toml"
    scen.write_text(COLLIDING_CUT_IN)
    out = tmp_path / "out"
    assert main(["run", str(scen), "-o", str(out), "-q", "--no-record"]) == status.VERDICT_FAIL
    assert json.loads((out / "result.json").read_text())["result"]["collision"] is True
    assert "1 collision(s)" in capsys.readouterr().out


def test_r157_judge_exits_3_on_fail_and_0_on_pass(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    points = tmp_path / "points"
    grids = ["--ve", "60:60:10", "--dv", "20:20:10", "--vy-fine", "1:1:1", "--vy-coarse", "1:1:1"]
    assert main(["r157", "points", *grids, "--scenarios", "cut-in", "-o", str(points)]) == 0
    pts = str(points / "r157_points.json")
    one = ["--sample", "1", "-j", "1", "-q"]  # the boundary + 2 m point, Preventable
    # no perception: the ego never brakes for the car cutting in
    blind = main(["r157", "judge", pts, *one, "--perception", "none", "-o", str(tmp_path / "n")])
    assert "FAIL: 0/1 Preventable points passed" in capsys.readouterr().out
    assert blind == status.VERDICT_FAIL
    seeing = main(["r157", "judge", pts, *one, "-o", str(tmp_path / "p")])
    assert "PASS: 1/1 Preventable points passed" in capsys.readouterr().out
    assert seeing == status.OK
    rows = list(csv.DictReader((tmp_path / "p" / "judge.csv").open()))
    assert [r["verdict"] for r in rows] == ["pass"]
