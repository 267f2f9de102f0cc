"""LateralDistanceAction on SUMO: continuous, the actor stays a freespace distance to the left
of its reference while the reference shifts across its lane; not continuous with a maximum
acceleration, it moves there in the sinusoidal time that acceleration allows."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from openscenario_files import (
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

SHIFT = """<LateralAction><LaneOffsetAction continuous="false"><LaneOffsetActionDynamics dynamicsShape="sinusoidal" maxLateralAcc="0.5"/>
<LaneOffsetTarget><AbsoluteTargetLaneOffset value="-0.6"/></LaneOffsetTarget></LaneOffsetAction></LateralAction>"""


def _keep(continuous: str, dyn: str = "") -> str:
    return f"""<LateralAction><LateralDistanceAction entityRef="Ref" distance="1.0" freespace="true" continuous="{continuous}"
displacement="leftToReferencedEntity" coordinateSystem="entity">{dyn}</LateralDistanceAction></LateralAction>"""


def _run(tmp_path: Path, keep: str, until: float) -> dict[float, tuple[float, float]]:
    init = (
        teleport_speed("Ego", -5, 20, 10)
        + teleport_speed("Ref", -4, 80, 10)
        + teleport_speed("Car", -4, 90, 10, offset=0.0)
    )
    init = init.replace('laneId="-4" offset="0.0" s="90"', 'laneId="-3" offset="0.0" s="80"')
    stories = story("Car", keep, time_condition(0.0, "k", "none"), "Keep")
    stories += story("Ref", SHIFT, time_condition(1.0, "s"), "Shift")
    seen: dict[float, tuple[float, float]] = {}

    def on_step(sim, world, report, engine) -> None:
        seen[round(report.time, 2)] = (engine.actors["Ref"].t, engine.actors["Car"].t)

    run_scenario(
        write(tmp_path / "l.xosc", scenario_xml({"Ego": "", "Ref": "", "Car": ""}, init, stories)),
        tmp_path,
        until=until,
        on_step=on_step,
    )
    return seen


def test_continuous_lateral_distance_follows_the_reference(tmp_path: Path) -> None:
    seen = _run(tmp_path, _keep("true"), 6.0)
    # 1 m between the 2 m wide boxes: the reference points 3 m apart, from the first update on
    gaps = [car - ref for t, (ref, car) in seen.items() if t >= 0.1]
    assert max(abs(g - 3.0) for g in gaps) < 1e-9
    assert seen[5.5][0] == pytest.approx(seen[0.5][0] - 0.6, abs=1e-9)  # the reference did move


def test_lateral_distance_reached_with_its_maximum_acceleration(tmp_path: Path) -> None:
    seen = _run(tmp_path, _keep("false", '<DynamicConstraints maxAcceleration="1.0"/>'), 3.0)
    ref0, car0 = seen[0.0]
    # the car starts one 3.5 m lane left: 0.5 m to go, set when the action starts (0.05 s),
    # in pi sqrt(0.5 / (2 * 1.0)) s; the reference's later shift does not move the goal
    assert car0 - ref0 == pytest.approx(3.5)
    duration = math.pi * math.sqrt(0.5 / 2.0)
    done = [t for t, (ref, car) in seen.items() if abs(car - (ref0 + 3.0)) < 1e-9]
    assert done and 0.05 + duration <= done[0] + 0.05 < 0.05 + duration + 0.1


def _override(tmp_path: Path) -> tuple[dict[float, tuple[float, float]], list]:
    """Car (lane -4, 30 m/s) held continuously 0.5 m free right of Ref (lane -3, centre
    t = -4.5) from 0 s; from 1 s a second story moves it to 1 m left of Ref's reference point
    (not continuous, DynamicConstraints with only maxAcceleration = 7 m/s^2)."""
    right = """<LateralAction><LateralDistanceAction entityRef="Ref" distance="0.5" freespace="true" continuous="true"
displacement="rightToReferencedEntity" coordinateSystem="road"/></LateralAction>"""
    left = """<LateralAction><LateralDistanceAction entityRef="Ref" distance="1.0" freespace="false" continuous="false"
displacement="leftToReferencedEntity" coordinateSystem="road"><DynamicConstraints maxAcceleration="7.0"/></LateralDistanceAction></LateralAction>"""
    init = (
        teleport_speed("Ego", -5, 20, 30)
        + teleport_speed("Ref", -3, 80, 30)
        + teleport_speed("Car", -4, 85, 30)
    )
    stories = story("Car", right, time_condition(0.0, "r", "none"), "Right")
    stories += story("Car", left, time_condition(1.0, "l", "none"), "Left")
    seen: dict[float, tuple[float, float]] = {}
    result = {}

    def on_step(sim, world, report, engine) -> None:
        seen[round(report.time, 2)] = (engine.actors["Car"].s, engine.actors["Car"].t)
        result["log"] = engine.tree.log

    run_scenario(
        write(tmp_path / "o.xosc", scenario_xml({"Ego": "", "Ref": "", "Car": ""}, init, stories)),
        tmp_path,
        until=3.5,
        on_step=on_step,
    )
    return seen, result["log"]


def test_held_lateral_distance_is_stopped_by_the_next_one(tmp_path: Path) -> None:
    seen, log = _override(tmp_path)
    # held at -4.5 - (0.5 + 2.0 / 2 + 2.0 / 2) = -7.0 until the second action starts
    assert all(t == pytest.approx(-7.0, abs=1e-9) for k, (s, t) in seen.items() if 0.1 <= k < 1.0)
    # the continuous action runs until the second one takes the lateral domain over
    right = [(t, tr) for t, _, n, tr in log if n == "RightAction" and tr != "startTransition"]
    left_start = [t for t, _, n, tr in log if n == "LeftAction" and tr == "startTransition"][0]
    assert right == [(left_start, "stopTransition")]
    # 3.5 m to -3.5 with a peak lateral acceleration of 7 m/s^2: pi sqrt(3.5 / 14) = pi / 2 s,
    # peak lateral speed 3.5 m/s (0.175 m a step); the speed along the path stays 30 m/s, so
    # the car keeps at least sqrt(1.5^2 - 0.175^2) = 1.4898 m of road a step (the old
    # keeper, never removed, pulled it back every step: 0 m a step)
    times = sorted(seen)
    steps = [seen[b][0] - seen[a][0] for a, b in zip(times, times[1:], strict=False)]
    assert min(steps) > 1.4897 and max(steps) <= 1.5 + 1e-9
    done = [k for k in times if abs(seen[k][1] + 3.5) < 1e-9]
    assert done and done[0] == pytest.approx(left_start + math.pi / 2, abs=0.051)
    assert all(abs(seen[k][1] + 3.5) < 1e-9 for k in times if k >= done[0])


def test_continuous_lateral_distance_within_its_maximum_speed(tmp_path: Path) -> None:
    seen = _run(tmp_path, _keep("true", '<DynamicConstraints maxSpeed="1.0"/>'), 6.0)
    # 0.5 m to go at 1 m/s (no acceleration limit): 0.05 m a step, there after ten steps;
    # then it holds 3 m from the reference (whose 0.6 m shift needs less than 1 m/s)
    ref0, car0 = seen[0.0]
    assert car0 - ref0 == pytest.approx(3.5)
    moved = [seen[round(0.05 * k, 2)][1] - car0 for k in range(1, 12)]
    assert moved == pytest.approx([-0.05 * min(k, 10) for k in range(1, 12)], abs=1e-9)
    gaps = [car - ref for t, (ref, car) in seen.items() if t >= 0.6]
    assert max(abs(g - 3.0) for g in gaps) < 1e-9
