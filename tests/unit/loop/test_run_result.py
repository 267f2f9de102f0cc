"""Run results: one list of result fields for result.json, results.csv, the sweep and the judge;
typed time series written to timeseries.csv."""

from __future__ import annotations

import csv
import json
import math

import numpy as np

from hiyari.bridge.loop.closed_loop import ScenarioHooks, _LaneWatch, _metrics
from hiyari.bridge.loop.result import (
    JUDGE_KEYS,
    RESULT_FIELDS,
    RESULT_KEYS,
    RunResult,
    write_result,
)
from hiyari.bridge.loop.stack.aeb import AEBStage, EgoCommand
from hiyari.bridge.loop.stack.interfaces import EgoStep
from hiyari.bridge.loop.toml_runs import preset_doc
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.bridge.studies.sweep import RESULT_KEYS as SWEEP_KEYS
from hiyari.risk.metrics.ground_truth import TruthConfig
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.world_state import WorldState


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


def _world(t: float, lane: str = "e_0") -> WorldState:
    """The ego alone on edge e (lane ``lane``), at 20 m/s."""
    o = np.array(["ego"], dtype=object)
    one = np.ones(1)
    return WorldState(
        t, o, np.zeros(1, np.int8), np.array([[20.0 * t, 0.0, 0.0]]), np.zeros(1),
        20.0 * one, np.zeros(1), 4.8 * one, 1.9 * one, 1.5 * one,
        np.array([lane], dtype=object), np.array(["e"], dtype=object),
    )  # fmt: skip


def _step(t: float, stage: int) -> EgoStep:
    cmd = EgoCommand(t, 0.0, 0.0, AEBStage(stage), 0.0, math.inf, "")
    return EgoStep(cmd, [], ObjectList.empty(t, "fusion", np.eye(4)))


def test_a_stage_reached_has_its_time():
    """result.json said aeb_max_stage 1 with aeb_first_time_s null (issue 30, item 5)."""
    res, hooks, truth = RunResult("warn"), ScenarioHooks(), TruthConfig()
    for k, stage in enumerate([0, 1, 1, 0, 2]):
        t = 0.05 * k
        world = _world(t)
        _metrics(res, world, 0, world.pose(0), _step(t, stage), hooks, truth)
    d = res.as_dict()
    assert d["aeb_max_stage"] == 2
    assert d["aeb_first_time_s"] == 0.05 and d["aeb_brake_time_s"] == 0.2
    # the warning and the braking 0.1 s after it, nothing in conflict: one false activation
    # (FalseActivationRule.join_gap)
    assert d["false_activations"] == 1


def test_leaving_the_lane_is_noted_within_an_edge_only():
    res = RunResult("lanes")
    watch = _LaneWatch()
    for k, (edge, lane) in enumerate([("e", "e_0"), (":j", ":j_0"), ("f", "f_1"), ("f", "f_1")]):
        w = _world(0.05 * k, lane)
        w.edge[0] = edge
        watch.update(res, w, 0)
    assert math.isnan(res.lane_left_time)  # on to the next edge: following the lane
    w = _world(0.25, "f_0")
    w.edge[0] = "f"
    watch.update(res, w, 0)
    assert res.lane_left_time == 0.25
