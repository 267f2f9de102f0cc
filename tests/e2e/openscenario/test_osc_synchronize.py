"""SynchronizeAction on SUMO: the actor reaches its target when the (stack-driven) master
reaches its own, by adjusting its speed only; with a final speed and a steady state (by
distance or by time) it holds the final speed over the last stretch; without a final speed it
drives at remaining distance over the master's time to go."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from openscenario_files import (
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

DT = 0.05
#: The master reaches s = 150 at t = 10 s (50 m ahead of its start at 10 m/s).
MASTER_TARGET, ACTOR_TARGET = 150.0, 250.0


def _sync(final: str) -> str:
    return f"""<SynchronizeAction masterEntityRef="Ego">
<TargetPositionMaster><LanePosition roadId="0" laneId="-4" s="{MASTER_TARGET}"/></TargetPositionMaster>
<TargetPosition><LanePosition roadId="0" laneId="-3" s="{ACTOR_TARGET}"/></TargetPosition>{final}</SynchronizeAction>"""


def _run(tmp_path: Path, final: str) -> tuple[np.ndarray, object]:
    text = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -4, 50, 10) + teleport_speed("Car", -3, 100, 0),
        story("Car", _sync(final), time_condition(0, "go", "none")),
    )
    rows: list[tuple[float, float, float, float]] = []

    def on_step(sim, world, report, engine) -> None:
        # the master as SUMO has it now; the actor as the engine has just moved it, for the
        # next step (so at report.time + DT): both on the road along x, reference points
        car = engine.actors["Car"]
        rows.append((report.time, engine.pose_of("Ego").s, car.s, car.v))

    engine, _ = run_scenario(
        write(tmp_path / "s.xosc", text), tmp_path, until=12.0, dt=DT, on_step=on_step
    )
    return np.array(rows), engine


def _arrival(t: np.ndarray, s: np.ndarray, target: float) -> float:
    k = int(np.argmax(s >= target))
    return float(t[k - 1] + (target - s[k - 1]) / (s[k] - s[k - 1]) * (t[k] - t[k - 1]))


@pytest.mark.parametrize(
    "steady", ['<TargetDistanceSteadyState distance="30"/>', '<TargetTimeSteadyState time="2"/>']
)
def test_final_speed_with_steady_state_meets_at_the_targets(tmp_path: Path, steady: str) -> None:
    rec, engine = _run(
        tmp_path, f'<FinalSpeed><AbsoluteSpeed value="15">{steady}</AbsoluteSpeed></FinalSpeed>'
    )
    t, ego_s, car_s, car_v = rec.T
    t_master, t_actor = _arrival(t, ego_s, MASTER_TARGET), _arrival(t + DT, car_s, ACTOR_TARGET)
    assert t_master == pytest.approx(10.0, abs=1e-6)
    # both reach their targets within a millisecond: 1.5 cm at 15 m/s
    assert abs(t_actor - t_master) < 1e-3
    # the last 30 m (2 s at 15 m/s) at the final speed, which the actor keeps after the action
    steady = (car_s >= ACTOR_TARGET - 30 + 0.1) & (t + DT < 11.0)
    assert steady.sum() > 30 and np.allclose(car_v[steady], 15.0, atol=1e-3)
    ended = [x for x in engine.tree.log if x[2] == "SAction" and x[3] == "endTransition"]
    assert len(ended) == 1 and abs(ended[0][0] - 10.0) <= DT + 1e-9


def test_without_final_speed_the_actor_averages_its_way(tmp_path: Path) -> None:
    rec, _ = _run(tmp_path, "")
    t, ego_s, car_s, car_v = rec.T
    assert abs(_arrival(t + DT, car_s, ACTOR_TARGET) - _arrival(t, ego_s, MASTER_TARGET)) < 1e-3
    # from t = 0.05 (the event starts one update after its act): 150 m in 9.95 s
    assert car_v[1] == pytest.approx(150 / 9.95)
