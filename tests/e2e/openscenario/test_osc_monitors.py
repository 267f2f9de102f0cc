"""MonitorDeclarations and SetMonitorAction: the storyboard sets a declared monitor, which the
engine holds for the run's evaluation; an undeclared monitor is one line naming the file."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    run_scenario,
    scenario_xml,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.errors import HiyariError


def _file(tmp_path: Path, ref: str) -> Path:
    stories = f"""<Story name="S"><Act name="A"><ManeuverGroup maximumExecutionCount="1" name="G">
<Actors selectTriggeringEntities="false"/><Maneuver name="M"><Event name="E" priority="override">
<Action name="fail"><GlobalAction><SetMonitorAction monitorRef="{ref}" value="false"/></GlobalAction></Action>
<StartTrigger><ConditionGroup>{time_condition(0.99, "t", "none")}</ConditionGroup></StartTrigger></Event></Maneuver></ManeuverGroup>
<StartTrigger><ConditionGroup>{time_condition(0, "go", "none")}</ConditionGroup></StartTrigger></Act></Story>"""
    text = scenario_xml({"Ego": ""}, teleport_speed("Ego", -4, 20, 10), stories)
    text = text.replace(
        "<CatalogLocations>",
        '<MonitorDeclarations><MonitorDeclaration name="kept" value="true"/></MonitorDeclarations><CatalogLocations>',
    )
    return write(tmp_path / "m.xosc", text)


def test_set_monitor(tmp_path: Path) -> None:
    seen = {}
    run_scenario(_file(tmp_path, "kept"), tmp_path, until=1.5,
                 on_step=lambda s, w, r, e: seen.__setitem__(round(r.time, 2), e.values.get("monitor", "kept", "").text))  # fmt: skip
    assert seen[0.95] == "true" and seen[1.0] == "false"


def test_undeclared_monitor(tmp_path: Path) -> None:
    with pytest.raises(
        HiyariError, match=r"m\.xosc:\d+: no monitor 'gone' is declared \(declared: kept\)"
    ):
        run_scenario(_file(tmp_path, "gone"), tmp_path, until=1.5)
