"""A worker process that dies mid-run (the pool's test-only SIGSEGV hook) costs one run of
``hiyari evaluate``, ``hiyari r157 judge`` or ``hiyari study sct``, never the campaign: the
run is recorded as crashed, the report counts it, the command exits RUNS_CRASHED (4), and the
same command again runs it. (Sweeps: tests/e2e/studies/test_sweep.py; the pool: tests/unit/studies/test_pool_crash.py.)"""

from __future__ import annotations

import csv
import json
from pathlib import Path

from hiyari.bridge.cli import status
from hiyari.bridge.cli.main import main
from hiyari.bridge.studies.pool import TEST_CRASH_ENV

SIGSEGV = "worker process died of SIGSEGV (signal 11)"


def test_evaluate_records_the_crashed_run_and_retries_it(tmp_path: Path, monkeypatch, capsys):
    # two lead-braking runs an ego without perception hits (both fail, both are recorded)
    out = tmp_path / "eval"
    argv = ["evaluate", "--cells", "M02-front-2L", "--runs-per-cell", "2", "--perception",
            "none", "-j", "2", "-q", "-o", str(out)]  # fmt: skip
    monkeypatch.setenv(TEST_CRASH_ENV, "1")
    assert main(argv) == status.RUNS_CRASHED
    printed = capsys.readouterr()
    assert "2 runs, 0 passed, 1 failed, 1 crashed" in printed.out
    assert "1 run(s) crashed" in printed.err
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [(r["run_id"], r["passed"]) for r in rows] == [
        ("M02-front-2L-000", "False"),
        ("M02-front-2L-001", "crashed"),
    ]
    crashed = rows[1]
    assert crashed["cause"] == SIGSEGV and crashed["params"].startswith("ego_speed=")
    assert crashed["collision"] == "" and crashed["cell"] == "M02-front-2L"
    assert "<td>crashed runs" in (out / "report.html").read_text()
    assert [p.name for p in (out / "recordings").glob("*.mcap")] == ["M02-front-2L-000.mcap"]
    # the same command again runs the crashed one (the hook names a task no longer there)
    assert main(argv) == status.VERDICT_FAIL
    assert "2 runs, 0 passed, 2 failed, 0 crashed" in capsys.readouterr().out
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [r["passed"] for r in rows] == ["False", "False"]
    assert rows[1]["params"] == crashed["params"] and rows[1]["collision"] == "True"
    assert (out / "recordings" / "M02-front-2L-001.mcap").is_file()


def test_r157_judge_counts_the_crashed_point(tmp_path: Path, monkeypatch, capsys):
    points = tmp_path / "points"
    grids = ["--ve", "60:60:10", "--dv", "20:20:10", "--vy-fine", "1:1:1", "--vy-coarse", "1:1:1"]
    assert main(["r157", "points", *grids, "--scenarios", "cut-in", "-o", str(points)]) == 0
    pts = str(points / "r157_points.json")
    out = tmp_path / "judge"
    monkeypatch.setenv(TEST_CRASH_ENV, "0")
    argv = ["r157", "judge", pts, "--sample", "2", "-j", "2", "-q", "-o", str(out)]
    assert main(argv) == status.RUNS_CRASHED
    assert "1 point(s) crashed" in capsys.readouterr().out
    rows = list(csv.DictReader((out / "judge.csv").open()))
    assert [r["verdict"] for r in rows][0] == "crashed" and rows[0]["error"] == SIGSEGV
    assert rows[1]["verdict"] in ("pass", "n/a")
    assert json.loads((out / "summary.json").read_text())["perfect"]["crashed"] == 1
    monkeypatch.delenv(TEST_CRASH_ENV)
    assert main(argv) in (status.OK, status.VERDICT_FAIL)
    rows = list(csv.DictReader((out / "judge.csv").open()))
    assert "crashed" not in [r["verdict"] for r in rows]


def test_study_reports_the_crashed_arm_as_incomplete(tmp_path: Path, monkeypatch, capsys):
    """10 simulated minutes of both arms; the baseline's worker dies (the SCT arm starts
    first, so the baseline is task 1): the report and summary count it, exit 4."""
    out = tmp_path / "study"
    monkeypatch.setenv(TEST_CRASH_ENV, "1")
    argv = ["study", "sct", "-o", str(out), "--days", str(600 / 86400), "--seed", "3",
            "--runs", "1", "--variants", "unsignalised", "-j", "2", "-q"]  # fmt: skip
    assert main(argv) == status.RUNS_CRASHED
    err = capsys.readouterr().err
    assert "1 run(s) crashed and are left out of the report" in err
    assert "unsignalised baseline seed 3: " + SIGSEGV in err
    text = (out / "report.md").read_text()
    assert "**Incomplete**: unsignalised baseline: 1 run(s) crashed" in text
    arms = {a["arm"]: a for a in json.loads((out / "summary.json").read_text())["arms"]}
    assert (arms["baseline"]["crashed_runs"], arms["sct"]["crashed_runs"]) == (1, 0)
    assert arms["baseline"]["vehicles"] == 0 and arms["sct"]["vehicles"] > 15
