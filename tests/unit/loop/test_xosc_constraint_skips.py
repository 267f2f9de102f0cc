"""A distribution's runs whose parameters break the scenario's ConstraintGroups are skipped,
not executed (OpenSCENARIO 1.3: the constraints define the valid values), and counted: run k
keeps its index and seed, and its reason names the parameter, its value and the evaluated
bounds it breaks. A violating run #0 no longer rejects the file (the upstream ALKS 4_3_1,
4_3_2 and 4_4_1 variation files)."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    DETERMINISTIC_VIOLATING,
    constrained_template,
    distribution_xml,
    stochastic_violating,
    write,
)

from hiyari.bridge.cli import status
from hiyari.bridge.cli.main import main
from hiyari.bridge.loop.spec import EgoSetup, count_text
from hiyari.bridge.loop.xosc_runs import load_plan
from hiyari.errors import HiyariError


def _dist(tmp_path: Path, body: str) -> Path:
    return write(
        tmp_path / "variation.xosc", distribution_xml(constrained_template(tmp_path), body)
    )


def test_deterministic_runs_keep_their_index_and_seed(tmp_path: Path) -> None:
    plan = load_plan(_dist(tmp_path, DETERMINISTIC_VIOLATING), EgoSetup(seed=7))
    runs = plan.expand()
    assert [(r.index, r.seed, r.params) for r in runs] == [
        (1, 8, {"Speed": "10", "Offset": "0.0"}),
        (2, 9, {"Speed": "10", "Offset": "1.75"}),
    ]
    assert [(s.index, s.seed) for s in plan.skipped] == [(0, 7), (3, 10), (4, 11), (5, 12)]
    reasons = [s.reason for s in plan.skipped]
    # the bound of Speed is $MaxSpeed: its value (20.0) is what the message gives
    assert reasons == [
        "Offset = -1.75 breaks greaterThan -1.75",
        "Speed = 30.0 breaks lessOrEqual 20.0; Offset = -1.75 breaks greaterThan -1.75",
        "Speed = 30.0 breaks lessOrEqual 20.0",
        "Speed = 30.0 breaks lessOrEqual 20.0",
    ]
    assert plan.skipped[0].label() == (
        "constrained_template#0: skipped (constraint: Offset = -1.75 breaks greaterThan -1.75)"
    )
    assert count_text(plan) == "6 run(s), 4 skipped: constraint"


def test_stochastic_runs_are_checked_one_by_one(tmp_path: Path) -> None:
    """Seed 3 draws a violating run #0 and violating later runs (checked below): each run is
    kept exactly when -1.75 < Offset <= 1.5 + 0.25 and LaneId is -1 or -2."""
    plan = load_plan(_dist(tmp_path, stochastic_violating(40, 3)))
    kept, skipped = plan.expand(), plan.skipped
    assert 0 in {s.index for s in skipped} and len(kept) >= 5 and len(skipped) >= 5
    assert sorted([r.index for r in kept] + [s.index for s in skipped]) == list(range(40))
    for r in kept:
        assert -1.75 < float(r.params["Offset"]) <= 1.75 and r.params["LaneId"] == "-1"
        assert r.seed == 1 + r.index
    for s in skipped:
        offset, lane = float(s.params["Offset"]), s.params["LaneId"]
        assert not (-1.75 < offset <= 1.75) or lane == "-3"
        if offset > 1.75:  # the bound is the expression ${1.5 + 0.25}, given evaluated
            assert f"Offset = {s.params['Offset']} breaks lessOrEqual 1.75" in s.reason
        if lane == "-3":  # the value fits none of the two groups: both are named
            assert "LaneId = -3 breaks every constraint group: [equalTo -1] [equalTo -2]" in (
                s.reason
            )


def test_every_run_skipped_is_one_line_error(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    body = DETERMINISTIC_VIOLATING.replace('<Element value="10"/>', '<Element value="25"/>')
    path = _dist(tmp_path, body)
    with pytest.raises(HiyariError, match="every run breaks the scenario's ConstraintGroups"):
        load_plan(path)
    assert main(["sweep", str(path), "--dry-run", "-o", str(tmp_path / "o")]) == status.ERROR
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "6 runs, 6 skipped: constraint; run #0: Speed = 25.0" in err[0]


def test_sweep_dry_run_counts_past_max_runs(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    path = _dist(tmp_path, DETERMINISTIC_VIOLATING)
    argv = ["sweep", str(path), "--dry-run", "--max-runs", "1", "-o", str(tmp_path / "o")]
    assert main(argv) == status.OK
    out = capsys.readouterr().out.splitlines()
    assert (
        "constrained_template#4: skipped (constraint: Speed = 30.0 breaks lessOrEqual 20.0)" in out
    )
    assert out[-1].startswith("6 run(s), 4 skipped: constraint; more than --max-runs 1")
    assert not (tmp_path / "o").exists()
