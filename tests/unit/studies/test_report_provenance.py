"""The catalogue report's traceability rows and users' units, by hand."""

from __future__ import annotations

from pathlib import Path

from hiyari.bridge.studies.catalogue.evaluation.campaign import CatalogueOptions
from hiyari.bridge.studies.catalogue.evaluation.provenance import (
    format_params,
    git_commit,
    in_user_units,
    run_configuration,
)
from hiyari.bridge.studies.catalogue.evaluation.runner import RunConfig


def test_users_units_by_hand():
    assert in_user_units("ego_speed", 25.0) == "90.0 km/h"
    assert in_user_units("speed_delta", -5.0) == "-18.0 km/h"
    assert in_user_units("decel", 4.905) == "4.91 m/s² (0.50 g)"
    assert in_user_units("gap", 12.345) == "12.35 m"
    assert in_user_units("plus_one_speed", 0.4) == "0.40 x ego speed"
    line = format_params({"ego_speed": 20.0, "lead_thw": 1.5})
    assert line == "ego speed 72.0 km/h; ego's time headway to its lead 1.50 s"


def test_git_commit_outside_a_checkout(tmp_path: Path):
    assert git_commit(tmp_path).startswith("not available")
    here = git_commit()
    assert len(here.split()[0]) == 40 or here.startswith("not available")


def test_run_configuration_rows(tmp_path: Path):
    options = CatalogueOptions(RunConfig(tmp_path), runs_per_cell=3, seed=7, only=("M03",))
    conf = run_configuration(options, "hiyari evaluate --cells M03", 12.34, tmp_path)
    assert conf["cells"] == "M03 (--cells)" and conf["runs per cell"] == "3"
    assert conf["seeds"].startswith("7: per cell s = crc32(cell key) xor 7")
    assert conf["range: ego speed"] == "60.0 km/h to 120.0 km/h"
    assert conf["range: deceleration"] == "2.94 m/s² (0.30 g) to 7.85 m/s² (0.80 g)"
    assert conf["wall time of this invocation"] == "12.3 s"
    assert "+ 1 m/s" in conf["pass rule"] and "scenario ends" in conf["C&C reference driver"]
    assert conf["date (UTC)"].endswith("+00:00") and "version numpy" in conf
