"""TraveledDistanceCondition on SUMO: the distance an entity has travelled since the scenario
started (the integral of its speed), for a scripted actor whose speed steps up and for the
stack-driven ego."""

from __future__ import annotations

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


def _traveled(entity: str, value: float, name: str) -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="rising"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="{entity}"/></TriggeringEntities>
<EntityCondition><TraveledDistanceCondition value="{value}"/></EntityCondition></ByEntityCondition></Condition>"""


SPEED_20 = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="20"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def test_traveled_distance_of_actor_and_ego(tmp_path: Path) -> None:
    # Car: 10 m/s to t = 1, then 20 m/s: 25 m at t = 1.75; Ego: 8 m/s, 20 m at t = 2.5
    stories = story("Car", SPEED_20, time_condition(0.99, "t1", "none"), "Up")
    stories += story("Car", SPEED_20, _traveled("Car", 24.99, "car25"), "CarDone")
    stories += story("Car", SPEED_20, _traveled("Ego", 19.99, "ego20"), "EgoDone")
    text = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -1, 20, 8) + teleport_speed("Car", -1, 100, 10),
        stories,
    )
    engine, _ = run_scenario(write(tmp_path / "d.xosc", text), tmp_path, until=3.0)
    started = {
        n: t for t, kind, n, tr in engine.tree.log if kind == "event" and tr == "startTransition"
    }
    assert started["CarDoneE"] == pytest.approx(1.75)
    assert started["EgoDoneE"] == pytest.approx(2.5)
