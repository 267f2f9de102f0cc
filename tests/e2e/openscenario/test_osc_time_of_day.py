"""TimeOfDayCondition: the environment's time of day, running on with the scenario when its
TimeOfDay is animated, compared with the condition's date and time."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import run_scenario, scenario_xml, story, teleport_speed, write

NOOP = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="10"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


@pytest.mark.parametrize("animated, expected", [("true", 2.5), ("false", None)])
def test_time_of_day(tmp_path: Path, animated: str, expected: float | None) -> None:
    env = f"""<GlobalAction><EnvironmentAction><Environment name="e"><TimeOfDay animation="{animated}" dateTime="2026-06-21T20:59:57.5"/>
</Environment></EnvironmentAction></GlobalAction>"""
    cond = """<Condition name="nine" delay="0" conditionEdge="none"><ByValueCondition>
<TimeOfDayCondition dateTime="2026-06-21T21:00:00" rule="greaterOrEqual"/></ByValueCondition></Condition>"""
    init = env + teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -3, 50, 10)
    engine, _ = run_scenario(
        write(
            tmp_path / "t.xosc",
            scenario_xml({"Ego": "", "Car": ""}, init, story("Car", NOOP, cond, "Nine")),
        ),
        tmp_path,
        until=4.0,
    )
    started = [t for t, kind, n, tr in engine.tree.log if n == "NineE" and tr == "startTransition"]
    assert (started[0] if started else None) == (pytest.approx(expected) if expected else None)
