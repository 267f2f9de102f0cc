"""Near misses are verdicts too (issue 30, item 5): in the ALKS partially-blocking-target file
the ego passes the pedestrian at 60 km/h with 0.25 m of lateral clearance, which is no
collision but must be a near miss in result.json and in the ALKS table."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from openscenario_files import ALKS

from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.spec import EgoSetup
from hiyari.bridge.loop.xosc_runs import load_plan
from hiyari.bridge.studies.alks import AlksTask, markdown, row_of

PARTIALLY_BLOCKING = ALKS / "alks_scenario_4_2_2_partially_blocking_target_template.xosc"
#: the pedestrian 60 m ahead instead of 500 m: the same pass, a 14 s run instead of 40 s
NEARER = {"TargetBlocking_InitPosition_LongitudinalOffset_m": "60"}


@pytest.fixture(scope="module")
def passed(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    out = tmp_path_factory.mktemp("alks_4_2_2")
    (run,) = load_plan(PARTIALLY_BLOCKING, EgoSetup(perception="perfect"), NEARER).expand()
    with run.spec() as spec:
        res = execute(spec, RunOptions(out_dir=out))
    assert res.verdict() == "near miss"
    return json.loads((out / "result.json").read_text())["result"], out


def test_the_pedestrian_passed_at_a_quarter_metre_is_a_near_miss(passed):
    d, _ = passed
    assert d["collision"] is False and d["tested"] is True
    assert d["near_misses"] == 1
    assert d["min_vru_clearance_m"] == pytest.approx(0.25, abs=0.01)
    (p,) = d["passes"]
    assert p["actor"] == "TargetBlocking" and p["vru"] and p["near_miss"]
    assert p["ego_speed_kmh"] == pytest.approx(60.0, abs=0.5)
    assert p["limit_m"] > 1.5  # a VRU at 60 km/h: 0.5 m + 0.08 s x 16.7 m/s


def test_the_alks_table_says_near_miss(passed):
    d, out = passed
    row = row_of(AlksTask(PARTIALLY_BLOCKING, "perfect", out), d, 1.0)
    assert row["verdict"] == "near miss" and row["near_misses"] == 1
    md = markdown([row])
    assert "**near miss** (0.25 m)" in md
    assert "perfect: 1 tested, 0 not tested; 0 collisions, 1 near misses" in md
