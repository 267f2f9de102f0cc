"""Model scenarios in closed loop on real SUMO: the engine drives the scripted actors, the ego
stack the ego; verdicts from the ground-truth kernel, recordings read back and replayed."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from openscenario_files import ALKS, scenario_xml, story, teleport_speed, time_condition, write

from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.spec import EgoSetup, StackContext, default_stack, model_spec
from hiyari.bridge.openscenario.xosc.reader import read_scenario
from hiyari.bridge.record.reader import Recording


def test_stack_brakes_for_a_stopping_lead_and_the_gap_is_the_kernels(tmp_path: Path) -> None:
    """Lead 60 m ahead at 20 m/s brakes to a stop at 4 m/s^2 from t = 2 s; the ego stack (ACC +
    AEB on perfect perception) stops behind it: no collision, min gap > 0, the gap series is
    bumper to bumper (centre distance minus half lengths, both 5 m cars), and the ego ends
    standing while its ACC set speed was its Init speed (20 m/s)."""
    brake = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="linear" value="4.0" dynamicsDimension="rate"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="0.0"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""
    stop = f"<ConditionGroup>{time_condition(14.0, 'end', 'none')}</ConditionGroup>"
    xml = scenario_xml(
        {"Ego": "", "Lead": ""},
        teleport_speed("Ego", -4, 5.0, 20.0) + teleport_speed("Lead", -4, 65.0, 20.0),
        story("Lead", brake, time_condition(2.0)),
        stop=stop,
    )
    sc = read_scenario(write(tmp_path / "brake.xosc", xml))
    seen = []
    res = execute(
        model_spec(sc),
        RunOptions(out_dir=tmp_path / "out"),
        on_step=lambda w, s, c: seen.append(
            np.hypot(*(w.xyz[w.index("Lead"), :2] - w.xyz[w.index("Ego"), :2])) - 5.0
        ),
    )
    assert not res.collision
    assert res.stop_trigger
    assert res.sim_seconds == pytest.approx(14.0 + 0.05, abs=1e-6)
    assert 0.0 < res.min_gap < 20.0
    gap = np.array(res.series.gap)
    assert np.allclose(gap, seen, atol=1e-6)
    assert res.min_gap == pytest.approx(gap.min(), abs=1e-9)
    assert res.series.ego_speed[0] == pytest.approx(20.0, abs=1e-6)
    assert res.final_speed < 0.1
    doc = json.loads((tmp_path / "out" / "result.json").read_text())
    assert doc["scenario"]["ego"] == "Ego" and doc["result"]["stop_trigger"] is True


def test_stack_less_ego_hits_the_stopping_lead(tmp_path: Path) -> None:
    """The same scenario with a stack that never brakes (perception none: nothing seen, ACC
    holds 20 m/s): the ego runs into the lead, the collision ends the run."""
    brake = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" value="0" dynamicsDimension="time"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="0.0"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""
    xml = scenario_xml(
        {"Ego": "", "Lead": ""},
        teleport_speed("Ego", -4, 5.0, 20.0) + teleport_speed("Lead", -4, 65.0, 0.0),
        story("Lead", brake, time_condition(0.0)),
        stop=f"<ConditionGroup>{time_condition(10.0, 'end', 'none')}</ConditionGroup>",
    )
    sc = read_scenario(write(tmp_path / "blind.xosc", xml))
    res = execute(model_spec(sc, EgoSetup(perception="none")))
    assert res.collision and res.collided_with == "Lead"
    assert not res.stop_trigger
    # ego front (5 + 1.4 + 2.5 = 8.9 m) to lead rear (65 + 1.4 - 2.5 = 63.9 m): 55 m at 20 m/s
    # close at 2.75 s of scenario time, overlapping on the next state; SUMO time runs one
    # step (the Init state) ahead of scenario time
    assert res.collision_time == pytest.approx(55.0 / 20.0 + 0.05 + 0.05, abs=1e-6)
    assert res.impact_speed == pytest.approx(20.0, abs=1e-6)


def test_alks_cut_in_recorded_and_replayed_with_a_user_stack(tmp_path: Path) -> None:
    """ALKS 4.4.1 (cut-in, no collision) with a stack factory: runs to its stop trigger, the
    recording holds every scored step with the file's entities, and the replay exports."""
    from hiyari.bridge.replay.export import export_html

    made: list[StackContext] = []

    def factory(ctx: StackContext):  # noqa: ANN202 - the factory protocol
        made.append(ctx)
        return default_stack(ctx)

    sc = read_scenario(next(ALKS.glob("alks_scenario_4_4_1_*.xosc")))
    out = tmp_path / "run"
    res = execute(model_spec(sc, EgoSetup(stack=factory)), RunOptions(out_dir=out, record=True))
    assert len(made) == 1 and made[0].ego_id == "Ego"
    assert made[0].set_speed == pytest.approx(60 / 3.6)  # Ego_InitSpeed_Ve0_kph = 60
    assert res.stop_trigger and not res.collision
    rec = Recording.open(out / "run.mcap")
    assert len(rec) == len(res.series.t)
    world, ego = rec.world_and_ego(len(rec) - 1)
    assert ego == "Ego" and "CutInVehicle" in set(world.ids.tolist())
    html = export_html(rec, tmp_path / "replay.html", frames=range(0, len(rec), 50), progress=False)
    assert html.stat().st_size > 10_000
