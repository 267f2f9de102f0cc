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
