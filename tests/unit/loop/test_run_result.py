"""Run results: one list of result fields for result.json, results.csv, the sweep and the judge;
typed time series written to timeseries.csv."""

from __future__ import annotations

import csv
import json
import math

from hiyari.bridge.loop.result import (
    JUDGE_KEYS,
    RESULT_FIELDS,
    RESULT_KEYS,
    RunResult,
    write_result,
)
from hiyari.bridge.loop.toml_runs import preset_doc
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.bridge.studies.sweep import RESULT_KEYS as SWEEP_KEYS


def _result() -> RunResult:
    r = RunResult("cut-in #0", collision=True, collided_with="other", collision_time=3.25)
    r.impact_speed, r.relative_impact_speed, r.min_ttc, r.final_speed = 12.5, 5.0, 0.0, 10.0
    for k in range(3):
        s = r.series
        s.t.append(0.05 * k)
        s.ego_speed.append(12.5)
        s.ego_accel_cmd.append(-1.0 * k)
        s.gap.append(math.inf)
        s.ttc_true.append(2.0 - k)
        s.ttc_stack.append(math.inf)
        s.aeb_stage.append(k)
    return r


def test_one_list_of_result_fields():
    r = _result()
    d = r.as_dict()
    assert list(d) == [f.key for f in RESULT_FIELDS] + ["passes", "detection"]
    assert list(r.row()) == list(RESULT_KEYS) == list(SWEEP_KEYS)
    assert set(JUDGE_KEYS) <= set(RESULT_KEYS)
    # file units: km/h, rounded; infinite and missing values as None
    assert d["impact_speed_kmh"] == 45.0 and d["relative_impact_speed_kmh"] == 18.0
    assert d["min_gap_m"] is None and d["stop_distance_m"] is None
    assert d["collision_time_s"] == 3.25


def test_result_files_round_trip(tmp_path):
    r = _result()
    cs = ConcreteScenario("cut-in", "x", 0, 1, 10.0, 0.05, {"ve0_kmh": 45.0})
    write_result(r, preset_doc(cs), tmp_path)
    doc = json.loads((tmp_path / "result.json").read_text())
    assert doc["scenario"]["params"] == {"ve0_kmh": 45.0} and doc["scenario"]["index"] == 0
    assert doc["result"]["collided_with"] == "other"
    with (tmp_path / "timeseries.csv").open() as f:
        rows = list(csv.DictReader(f))
    # conflict_distance was never filled: no column for it
    assert list(rows[0]) == [
        "t",
        "ego_speed",
        "ego_accel_cmd",
        "gap",
        "ttc_true",
        "ttc_stack",
        "aeb_stage",
    ]
    assert [float(x["ego_accel_cmd"]) for x in rows] == [0.0, -1.0, -2.0]
    assert rows[0]["gap"] == "inf" and float(rows[2]["ttc_true"]) == 0.0
