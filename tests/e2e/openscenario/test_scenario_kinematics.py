"""The preset scenarios, run by the ScenarioEngine in SUMO, move the other vehicles exactly as
the C&C evaluator assumes (positions read back from the WorldState)."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.presets.scenarios import (
    PresetRun,
    ScenarioConstants,
    build_scenario,
)
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.risk.cc.trajectory import cut_in_tracks, cut_out_tracks, decel_tracks
from hiyari.traffic.simulation import SimConfig, Simulation
from hiyari.units import G

T = np.array([0.0, 0.5, 1.0, 2.0, 3.5, 6.0])
DT = 0.05


def _states(preset: PresetRun, until: float) -> list:
    """WorldStates of the preset's engine run (nobody drives the ego) up to script time
    ``until`` (s), one per step."""
    cfg = SimConfig(net=preset.network.path, step_length=DT, seed=1)
    k = ScenarioConstants()
    out = []
    with Simulation(cfg) as sim:
        engine = ScenarioEngine(preset.scenario, preset.roads, DT)
        engine.start(sim)
        while sim.time < until + k.lead_in - 1e-9:
            world = sim.step()
            engine.step(sim, world)
            out.append(world)
    return out


def _track(preset: PresetRun, states: list, name: str, times: np.ndarray) -> np.ndarray:
    """(len(times), 4) s (road, m), d (m left of the ego lane's centre), speed (m/s) and
    length (m) of ``name`` at script times ``times`` (s)."""
    k = ScenarioConstants()
    road = preset.scenario.storyboard.init[0].action.body.position.road
    rows = []
    for t in times:
        w = next(w for w in states if abs(w.time - (t + k.lead_in)) < 1e-6)
        i = w.index(name)
        rc = preset.roads.odr.locate(w.xyz[i : i + 1, 0], w.xyz[i : i + 1, 1], road)[0]
        rows.append((rc.s, rc.t, float(w.speed[i]), float(w.length[i])))
    return np.array(rows)


def _cs(stype: str, params: dict) -> ConcreteScenario:
    return ConcreteScenario(stype, stype, 0, 1, 10.0, DT, params)


@pytest.mark.parametrize("stype", ["cut-in", "cut-out", "decel"])
def test_scripts_match_annex_g_tracks(tmp_path, stype):
    k = ScenarioConstants()
    params = {
        "cut-in": {"ve0_kmh": 60.0, "vo0_kmh": 30.0, "dx0_m": 12.0, "vy_ms": 1.2},
        "cut-out": {"ve0_kmh": 60.0, "vy_ms": 1.5, "dx0_f_m": 30.0},
        "decel": {"ve0_kmh": 80.0, "gx_max_g": 0.6},
    }[stype]
    preset = build_scenario(_cs(stype, params), tmp_path)
    states = _states(preset, T[-1])
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
        got = _track(preset, states, name, T)
        front = got[:, 0] + got[:, 3] / 2 - s_front0
        # an OpenSCENARIO speed is along the path: the preset drives at hypot(vx, vy) while
        # the car moves sideways, and back at vx from the step after; the step the lateral
        # motion ends in has it too fast for part of the step (millimetres, see _sideways)
        assert front == pytest.approx(track.x_front_m, abs=5e-3)
        assert got[:, 1] == pytest.approx(track.y_m, abs=1e-9)


def test_cut_in_lateral_speed_and_decel_speed_through_the_engine(tmp_path):
    """Sampled every step: the cut-in car's lateral position falls at exactly vy from script
    time 0 until it is in the ego lane; the braking lead's speed follows ve0 - a t to 0."""
    k = ScenarioConstants()
    vy = 1.3
    cut_in = {"ve0_kmh": 60.0, "vo0_kmh": 40.0, "dx0_m": 20.0, "vy_ms": vy}
    preset = build_scenario(_cs("cut-in", cut_in), tmp_path / "a")
    t = np.round(np.arange(-1.0, 4.0, DT), 10)
    d = _track(preset, _states(preset, t[-1]), "other", t)[:, 1]
    expected = np.clip(k.lane_width - vy * np.maximum(t, 0.0), 0.0, None)
    assert np.abs(d - expected).max() < 0.05
    assert d[t < 0] == pytest.approx(k.lane_width, abs=1e-9)  # not before script time 0
    moving = (t > 0) & (t < k.lane_width / vy - DT)
    assert np.diff(d)[moving[1:]] == pytest.approx(-vy * DT, abs=1e-9)

    decel = {"ve0_kmh": 72.0, "gx_max_g": 0.5}
    preset = build_scenario(_cs("decel", decel), tmp_path / "b")
    ve0, a = 20.0, 0.5 * G
    t = np.round(np.arange(0.0, 5.5, DT), 10)
    got = _track(preset, _states(preset, t[-1]), "other", t)
    s_exact = np.where(t < ve0 / a, ve0 * t - a * t * t / 2, ve0**2 / (2 * a))
    assert got[:, 0] - got[0, 0] == pytest.approx(s_exact, abs=1e-9)
    assert got[:, 2] == pytest.approx(np.maximum(ve0 - a * t, 0.0), abs=1e-9)
    assert got[-1, 2] == 0.0
