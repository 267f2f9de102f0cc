"""The SUMO scenario scripts move the other vehicles exactly as the C&C evaluator assumes."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.bridge.scenario.presets import ScenarioConstants, build_scenario
from hiyari.bridge.scenario.toml_file import ConcreteScenario
from hiyari.risk.cc.trajectory import cut_in_tracks, cut_out_tracks, decel_tracks

T = np.array([0.0, 0.5, 1.0, 2.0, 3.5, 6.0])


def _front_and_lateral(sc, name: str, s_front0: float) -> tuple[np.ndarray, np.ndarray]:
    """Front bumper along the road from the ego's front at t = 0, and lateral offset (m)."""
    actor = next(a for a in sc.scripted if a.vid == name)
    rows = [actor.trajectory(t) for t in T]
    front = np.array([r[0] for r in rows]) + actor.length / 2 - s_front0
    return front, np.array([r[1] for r in rows])


@pytest.mark.parametrize("stype", ["cut-in", "cut-out", "decel"])
def test_scripts_match_annex_g_tracks(tmp_path, stype):
    k = ScenarioConstants()
    params = {
        "cut-in": {"ve0_kmh": 60.0, "vo0_kmh": 30.0, "dx0_m": 12.0, "vy_ms": 1.2},
        "cut-out": {"ve0_kmh": 60.0, "vy_ms": 1.5, "dx0_f_m": 30.0},
        "decel": {"ve0_kmh": 80.0, "gx_max_g": 0.6},
    }[stype]
    sc = build_scenario(ConcreteScenario(stype, stype, 0, 1, 10.0, 0.05, params), tmp_path)
    ve0 = params["ve0_kmh"] / 3.6
    s_front0 = k.ego_start_s + ve0 * k.lead_in
    if stype == "cut-in":
        ref = {
            "other": cut_in_tracks(
                ve0, params["vo0_kmh"] / 3.6, params["dx0_m"], params["vy_ms"], T
            )["other"]
        }
    elif stype == "cut-out":
        tr = cut_out_tracks(ve0, params["vy_ms"], params["dx0_f_m"], T)
        ref = {"lead": tr["lead"], "other": tr["stopped"]}
    else:
        ref = {"other": decel_tracks(ve0, params["gx_max_g"], T)["lead"]}
    for name, track in ref.items():
        front, d = _front_and_lateral(sc, name, s_front0)
        assert front == pytest.approx(track.x_front_m, abs=1e-9)
        assert d == pytest.approx(track.y_m, abs=1e-9)
