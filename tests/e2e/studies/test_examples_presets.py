"""The shipped inputs are what the README says: the sample ParameterValueDistribution under
examples/openscenario/ runs as the documented sweep command (real SUMO), and the preset
library has a file for every TOML scenario type, each one read and expanded."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest
from paths import REPO_ROOT

from hiyari.bridge.cli.main import main
from hiyari.bridge.openscenario.presets.toml_file import PARAMETERS, load_scenario

ROOT = REPO_ROOT
EXAMPLE = ROOT / "examples" / "openscenario"
LIBRARY = ROOT / "bridge" / "openscenario" / "presets" / "library"


@pytest.mark.slow
def test_sample_distribution_sweeps_on_its_own_road(tmp_path: Path) -> None:
    """`hiyari sweep distribution.xosc`: 3 gaps x 2 lateral speeds in file order, every run
    ok; with perfect perception no cut-in collides and, at one lateral speed, the smallest
    gap over the run grows with the gap at which the car cuts in."""
    out = tmp_path / "sweep"
    assert main(["sweep", str(EXAMPLE / "distribution.xosc"), "-o", str(out), "-j", "1",
                 "-q"]) == 0  # fmt: skip
    rows = list(csv.DictReader((out / "results.csv").open()))
    grid = [(r["CutIn_Gap_dx0_m"], r["CutIn_LateralSpeed_Vy_mps"]) for r in rows]
    assert grid == [(g, v) for g in ("15.0", "30.0", "45.0") for v in ("1.0", "2.0")]
    assert [r["status"] for r in rows] == ["ok"] * 6
    assert [r["collision"] for r in rows] == ["False"] * 6
    for vy in ("1.0", "2.0"):
        gaps = [float(r["min_gap_m"]) for r in rows if r["CutIn_LateralSpeed_Vy_mps"] == vy]
        assert gaps[0] < gaps[1] < gaps[2], gaps


def test_every_toml_scenario_type_has_a_library_file() -> None:
    types = {}
    for path in sorted(LIBRARY.glob("*.toml")):
        logical = load_scenario(path)
        assert logical.expand(), path  # expands into at least one run
        types.setdefault(logical.type, []).append(path.name)
    assert set(types) == set(PARAMETERS), types
