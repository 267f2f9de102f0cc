"""A file as third-party tools write it, through ``hiyari run --dry-run``: the ego named with
--ego (no entity has a name hiyari recognises), and the storyboard actions addressed to the
stack-driven ego warned about once per action kind when the run starts (SUMO started)."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest
from openscenario_files import scenario_xml, story, teleport_speed, time_condition, write

from hiyari.bridge.cli.main import main

SPEED = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="{v}"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""
CHANGE = """<LateralAction><LaneChangeAction><LaneChangeActionDynamics dynamicsShape="linear" dynamicsDimension="time" value="2"/>
<LaneChangeTarget><RelativeTargetLane entityRef="Car1" value="1"/></LaneChangeTarget></LaneChangeAction></LateralAction>"""


def test_ego_option_and_dropped_ego_action_warnings(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    init = teleport_speed("Car1", -1, 50, 10) + teleport_speed("Car2", -1, 90, 10)
    stories = (
        story("Car1", SPEED.format(v=5), time_condition(1), "A")
        + story("Car1", SPEED.format(v=7), time_condition(2), "B")
        + story("Car1", CHANGE, time_condition(3), "C")
        + story("Car2", SPEED.format(v=3), time_condition(1), "D")
    )
    path = write(tmp_path / "s.xosc", scenario_xml({"Car1": "", "Car2": ""}, init, stories))
    out = tmp_path / "out"
    with caplog.at_level(logging.WARNING):
        assert main(["run", str(path), "--ego", "Car1", "--dry-run", "-q", "-o", str(out)]) == 0
    lines = [r.getMessage() for r in caplog.records if r.name.endswith("loop.hooks")]
    tail = (
        "the ego is driven by hiyari's stack (give its controller the property "
        "hiyari:driver=storyboard to have the storyboard drive it)"
    )
    assert lines == [
        f"{path.resolve()}: 2 SpeedAction(s) on the ego 'Car1' not applied (AAction, "
        f"BAction): {tail}",
        f"{path.resolve()}: 1 LaneChangeAction(s) on the ego 'Car1' not applied (CAction): {tail}",
    ]
    assert not out.exists()
