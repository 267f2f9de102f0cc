"""The scenario engine on real SUMO: lane changes, speed changes and TTC triggers against
hand-computed values, and the 15 ALKS reference scenarios run to their stop triggers."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from openscenario_files import ALKS, run_scenario, scenario_xml, story, teleport_speed, write

from hiyari.traffic.world_state import WorldState

DT = 0.05
LANE_W = 3.5
# ALKS straight road: lane -4 centre at y = -8 (lanes -1 .. -3: 2 + 0.75 + 3.5 m), -5 at -11.5
Y_LANE = {-3: -4.5, -4: -8.0, -5: -11.5}


@pytest.fixture(scope="module")
def work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("engine")


def _shape(shape: str, x: float) -> float:
    x = min(1.0, max(0.0, x))
    return {
        "linear": x,
        "cubic": x * x * (3 - 2 * x),
        "sinusoidal": 0.5 * (1 - math.cos(math.pi * x)),
    }[shape]


@pytest.mark.parametrize("shape", ["sinusoidal", "cubic", "linear"])
def test_lane_change_follows_its_shape_in_the_world_state(work: Path, shape: str) -> None:
    """LaneChangeAction over 3 s from lane -5 to -4 (3.5 m left): the centre's y in the
    WorldState follows y0 + 3.5 f(t / 3) within 0.05 m at every step."""
    t_start = 1.0
    change = f"""<LateralAction><LaneChangeAction>
<LaneChangeActionDynamics dynamicsShape="{shape}" value="3.0" dynamicsDimension="time"/>
<LaneChangeTarget><AbsoluteTargetLane value="-4"/></LaneChangeTarget></LaneChangeAction></LateralAction>"""
    from openscenario_files import time_condition

    xml = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -3, 5.0, 20.0) + teleport_speed("Car", -5, 50.0, 20.0),
        story("Car", change, time_condition(t_start)),
    )
    samples = []

    def record(sim: object, world: WorldState, report: object, engine: object) -> None:
        k = world.index("Car")
        samples.append((report.time, world.xyz[k, 1], world.xyz[k, 0], world.heading[k]))

    run_scenario(write(work / f"lc_{shape}.xosc", xml), work, until=6.0, on_step=record)
    t, y, x, h = map(np.array, zip(*samples, strict=True))
    # the reference point (rear axle) is 1.4 m behind the box centre along the heading
    y_ref, x_ref = y - 1.4 * np.sin(h), x - 1.4 * np.cos(h)
    # the action starts on the state at t_start; the pose of that update shows one step later
    expected = Y_LANE[-5] + LANE_W * np.array([_shape(shape, (tt - t_start) / 3.0) for tt in t])
    assert np.max(np.abs(y_ref - expected)) < 0.05
    assert abs(y[-1] - Y_LANE[-4]) < 1e-6  # ends on the target lane's centre, heading straight
    # 20 m/s along the path meanwhile (the speed of an entity: the lane change takes its
    # lateral share out of the distance along the lane), 20 m/s along the lane before it
    assert np.allclose(np.hypot(np.diff(x_ref), np.diff(y_ref)), 20.0 * 0.05, atol=1e-6)
    before = t <= t_start  # scenario time 0: the Init state, s = 50 m
    assert np.allclose(x_ref[before], 50.0 + 20.0 * t[before], atol=1e-6)


def test_speed_action_linear_by_rate_reaches_target_at_computed_time(work: Path) -> None:
    """SpeedAction linear, rate 2 m/s^2, from 10 to 20 m/s started at t = 1 s: the target is
    reached (10 / 2) = 5 s later, at t = 6 s (+- one step), linearly in between."""
    from openscenario_files import time_condition

    speed = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="linear" value="2.0" dynamicsDimension="rate"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="20.0"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""
    xml = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -3, 5.0, 10.0) + teleport_speed("Car", -4, 30.0, 10.0),
        story("Car", speed, time_condition(1.0)),
    )
    samples = []
    run_scenario(
        write(work / "speed.xosc", xml),
        work,
        until=8.0,
        on_step=lambda sim, w, r, e: samples.append((r.time, w.speed[w.index("Car")])),
    )
    t, v = map(np.array, zip(*samples, strict=True))
    reached = t[np.argmax(v >= 20.0 - 1e-9)]
    assert abs(reached - 6.0) <= DT + 1e-9
    ramp = (t > 1.0 + 2 * DT) & (t < 6.0 - DT)
    assert np.allclose(v[ramp], 10.0 + 2.0 * (t[ramp] - 1.0), atol=1e-6)


def test_time_to_collision_condition_fires_where_hand_ttc_crosses(work: Path) -> None:
    """Ego at 20 m/s behind a lead at 10 m/s, bumper gap 100.25 m: TTC = gap / 10 m/s falls
    below 4 s when the gap is 40 m, at t = 6.025 s; the condition (freespace) fires on the
    first evaluated state after that, t = 6.05 s."""
    lead_front = 5.0 + 1.4 + 2.5 + 100.25  # ego front (rear axle 5 m) + gap, m
    lead_s = lead_front + 1.1  # lead's rear axle: 1.1 m ahead of its rear bumper
    marker = """<LateralAction><LaneOffsetAction continuous="false">
<LaneOffsetActionDynamics maxLateralAcc="1.0" dynamicsShape="sinusoidal"/>
<LaneOffsetTarget><AbsoluteTargetLaneOffset value="0.5"/></LaneOffsetTarget></LaneOffsetAction></LateralAction>"""
    ttc = """<Condition name="ttc" delay="0" conditionEdge="rising"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Ego"/></TriggeringEntities>
<EntityCondition><TimeToCollisionCondition value="4.0" freespace="true" rule="lessThan" relativeDistanceType="longitudinal" coordinateSystem="entity">
<TimeToCollisionConditionTarget><EntityRef entityRef="Lead"/></TimeToCollisionConditionTarget></TimeToCollisionCondition>
</EntityCondition></ByEntityCondition></Condition>"""
    xml = scenario_xml(
        {"Ego": "", "Lead": ""},
        teleport_speed("Ego", -4, 5.0, 20.0) + teleport_speed("Lead", -4, lead_s, 10.0),
        story("Lead", marker, ttc),
    )
    fired = []
    run_scenario(
        write(work / "ttc.xosc", xml),
        work,
        until=8.0,
        on_step=lambda sim, w, r, e: fired.extend(r.time for n in r.started if n == "SAction"),
    )
    assert len(fired) == 1
    assert fired[0] == pytest.approx(6.05, abs=1e-9)


ALKS_FILES = sorted(ALKS.glob("alks_scenario_*.xosc"))


@pytest.mark.slow
@pytest.mark.parametrize("path", ALKS_FILES, ids=lambda p: p.stem[14:19])
def test_alks_scenarios_run_to_their_stop_trigger(work: Path, path: Path) -> None:
    """Each ALKS scenario executes on SUMO until its stop trigger (the two 5-minute free
    drives until a 20 s limit: their last scripted event is at 3 s); the scripted actors do
    what the file says."""
    long_run = any(k in path.stem for k in ("4_1_1", "4_1_3"))
    engine, report = run_scenario(path, work, until=20.0 if long_run else 60.0)
    assert report.finished == (not long_run)
    log = {(kind, name, tr): t for t, kind, name, tr in engine.tree.log}
    if "4_4_1" in path.stem:  # cut-in: lane change of 3.5 m at a peak 2 m/s, sinusoidal
        t0 = log[("action", "CutInAction", "startTransition")]
        t1 = log[("action", "CutInAction", "endTransition")]
        assert t1 - t0 == pytest.approx(math.pi / 2 * 3.5 / 2.0, abs=DT + 1e-9)
        assert report.time == pytest.approx(t1 + 10.0 + DT, abs=1e-9)
    if "4_3_2" in path.stem:  # lead brakes from 60 km/h to a stop at the file's rate at 10 s
        a = float(engine.scenario.parameters["LeadVehicle_Deceleration_Rate_mps2"])
        t1 = log[("action", "BrakeAction", "endTransition")]
        assert t1 == pytest.approx(10.0 + (60 / 3.6) / a, abs=DT + 1e-9)
    if "4_2_3" in path.stem:  # pedestrian crosses 10 m at 5 km/h
        t0 = log[("action", "CrossAction", "startTransition")]
        t1 = log[("action", "CrossAction", "endTransition")]
        assert t1 - t0 == pytest.approx(10.0 / (5 / 3.6), abs=DT + 1e-9)
