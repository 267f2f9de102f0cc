"""``hiyari run`` and ``hiyari sweep`` on a distribution whose run #0 and later runs break the
scenario's ConstraintGroups: the violating runs are skipped and reported (the dry run's list
and count, the sweep's results.csv rows, the exit summaries); the others run, keeping their
indices and seeds."""

from __future__ import annotations

import csv
from pathlib import Path

from openscenario_files import (
    DETERMINISTIC_VIOLATING,
    constrained_template,
    distribution_xml,
    write,
)

from hiyari.bridge.cli import status
from hiyari.bridge.cli.main import main

SPEED = "constraint: Speed = 30.0 breaks lessOrEqual 20.0"


def _dist(tmp_path: Path) -> Path:
    template = constrained_template(tmp_path, stop_s=0.3)
    return write(tmp_path / "variation.xosc", distribution_xml(template, DETERMINISTIC_VIOLATING))


def test_run_dry_run_lists_skips_and_counts_past_max_runs(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    out = tmp_path / "out"
    argv = ["run", str(_dist(tmp_path)), "--dry-run", "--max-runs", "1", "-o", str(out)]
    assert main(argv) == status.OK
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "constrained_template#1 Speed=10 Offset=0.0: ready"
    assert f"constrained_template#5: skipped ({SPEED})" in lines
    assert lines[-1].startswith("6 run(s), 4 skipped: constraint; 1 checked up to their first")
    assert "1 more counted, not checked (--max-runs)" in lines[-1]
    assert not out.exists()


def test_run_and_sweep_skip_the_violating_runs(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    path = _dist(tmp_path)
    assert main(["run", str(path), "-q", "-o", str(tmp_path / "run")]) == status.OK
    printed = capsys.readouterr().out
    assert "6 run(s), 4 skipped: constraint, 0 collision(s)" in printed
    assert sorted(p.name for p in (tmp_path / "run").glob("run*")) == ["run0001", "run0002"]

    argv = ["sweep", str(path), "-q", "--in-process", "-o", str(tmp_path / "sweep")]
    assert main(argv) == status.OK
    assert "6 runs, 4 skipped: constraint; 2 ran now, 0 already done" in capsys.readouterr().out
    with (tmp_path / "sweep" / "results.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [(r["index"], r["seed"], r["status"]) for r in rows] == [
        ("0", "1", "skipped"), ("1", "2", "ok"), ("2", "3", "ok"),
        ("3", "4", "skipped"), ("4", "5", "skipped"), ("5", "6", "skipped"),
    ]  # fmt: skip
    assert rows[0]["error"] == "constraint: Offset = -1.75 breaks greaterThan -1.75"
    assert rows[4]["error"] == SPEED and rows[4]["Speed"] == "30"
    # a second call keeps the table: the skipped rows are not runs still to do
    assert main(argv) == status.OK
    assert "0 ran now, 2 already done" in capsys.readouterr().out
