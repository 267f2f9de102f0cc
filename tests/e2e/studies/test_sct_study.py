"""The incident study end to end on short real SUMO runs: seeds, report files, CLI errors."""

from __future__ import annotations

import csv
import json

import matplotlib.image
import numpy as np
import pytest

from hiyari.bridge.cli.main import main
from hiyari.bridge.studies.report.sct import write_report
from hiyari.bridge.studies.sct.study import StudyConfig, build_inputs, run_tasks
from hiyari.bridge.studies.sct.summary import summarise
from hiyari.risk.metrics.incidents import write_encounters_csv

pytestmark = pytest.mark.timeout(300)

# 5 simulated minutes of the unsignalised variant, both arms
CONFIG = StudyConfig(days=300 / 86400, runs=1, variants=("unsignalised",), seed=3)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("study")
    tasks = build_inputs(CONFIG, folder / "inputs")
    first = run_tasks(tasks, jobs=1)
    again = run_tasks(tasks, jobs=1)
    return folder, tasks, first, again


def test_same_seed_same_encounters(runs, tmp_path):
    _, tasks, first, again = runs
    assert [t.arm for t in tasks] == ["baseline", "sct"]
    for a, b in zip(first, again, strict=True):
        ca = write_encounters_csv(tmp_path / "a.csv", a.encounters).read_bytes()
        cb = write_encounters_csv(tmp_path / "b.csv", b.encounters).read_bytes()
        assert ca == cb
        assert np.array_equal(a.travel_time, b.travel_time)
        assert np.array_equal(a.incident_flags, b.incident_flags)
    base, sct = first
    assert len(base.encounters) > 0 and len(base.travel_time) > 12  # 17 cars in 5 min
    assert sct.interventions > 0 and base.interventions == 0
    # the SCT drivers give way more than SUMO's own: they lose more time
    assert sct.time_loss.mean() > base.time_loss.mean()


def test_report_files(runs):
    folder, _, results, _ = runs
    md = write_report(folder, CONFIG, results, wall_seconds=1.0)
    text = md.read_text()
    assert "| hiyari, unsignalised |" in text and "1990" in text
    rows = list(csv.DictReader((folder / "incidents.csv").open()))
    assert len(rows) == sum(len(r.incidents) for r in results)
    assert {r["arm"] for r in rows} <= {"baseline", "sct"}
    summary = json.loads((folder / "summary.json").read_text())
    arms = {(a["variant"], a["arm"]): a for a in summary["arms"]}
    assert arms[("unsignalised", "baseline")]["incidents"] == len(results[0].incidents)
    for name in ("incidents_bar.png", "ttc_sct_hist.png", "incidents_by_hour.png"):
        img = matplotlib.image.imread(folder / name)
        assert img.ndim == 3 and img.shape[0] > 100
    s = summarise(CONFIG, results)
    assert [x.arm for x in s] == ["baseline", "sct"]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--days", "-1"], "days must be > 0"),
        (["--variants", "roundabout"], "unknown variant"),
        (["--penetration", "2"], "penetration must be in 0..1"),
        (["--pet-threshold", "0"], "pet_threshold must be positive"),
    ],
)
def test_cli_rejects_bad_parameters(args, message, capsys, tmp_path):
    assert main(["study", "sct", "-o", str(tmp_path), *args]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("hiyari: error:") and message in err and "\n" not in err
