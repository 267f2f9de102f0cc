"""Two ObjectControllers on one entity, ActivateControllerAction choosing one by name: the
ego is the stack's under its first controller and the storyboard's under the second (property
hiyari:driver = storyboard), so a SpeedAction on it is a request to the stack before and is
applied after; an unknown controller name is one line naming the file."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    CAR,
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.errors import HiyariError

TWO = """<ObjectController name="stack"><Controller name="hiyari stack"><Properties/></Controller></ObjectController>
<ObjectController name="script"><Controller name="scripted"><Properties>
<Property name="hiyari:driver" value="storyboard"/></Properties></Controller></ObjectController>"""
SLOW = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="4"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def _activate(name: str) -> str:
    return f'<ControllerAction><ActivateControllerAction objectControllerRef="{name}" lateral="true" longitudinal="true"/></ControllerAction>'


def _file(tmp_path: Path, name: str) -> Path:
    ego = CAR.format(name="Ego") + TWO
    stories = story("Ego", SLOW, time_condition(0.5, "early"), "Early")
    stories += story("Ego", _activate(name), time_condition(1.0, "switch"), "Switch")
    stories += story("Ego", SLOW, time_condition(1.5, "late"), "Late")
    return write(
        tmp_path / "c.xosc", scenario_xml({"Ego": ego}, teleport_speed("Ego", -4, 20, 10), stories)
    )


def test_activating_the_second_controller_hands_the_ego_to_the_storyboard(tmp_path: Path) -> None:
    log = []

    def on_step(sim, world, report, engine) -> None:
        k = world.index("Ego")
        log.append((round(report.time, 2), report.ego_storyboard_driven, report.ego_requests,
                    float(world.speed[k]), float(world.xyz[k, 0])))  # fmt: skip

    run_scenario(_file(tmp_path, "script"), tmp_path, until=2.5, on_step=on_step)
    driven = {t: d for t, d, _, _, _ in log}
    requests = [(t, req) for t, _, req, _, _ in log if req]
    assert not driven[0.95] and driven[1.05]
    assert requests == [(0.5, ("EarlyAction",))]  # before the switch: the stack's to heed
    speed = {t: v for t, _, _, v, _ in log}
    assert speed[1.4] == pytest.approx(10.0) and speed[2.0] == pytest.approx(4.0)
    # taken over where the stack had it: 10 m/s throughout until the SpeedAction at 1.5
    x = {t: x for t, _, _, _, x in log}
    assert x[1.5] - x[0.0] == pytest.approx(15.0, abs=1e-6)


def test_unknown_controller_is_one_line(tmp_path: Path) -> None:
    with pytest.raises(
        HiyariError,
        match=r"c\.xosc:\d+: ActivateControllerAction: entity 'Ego' has no controller 'nope' \(its controllers: stack, script\)",
    ):
        run_scenario(_file(tmp_path, "nope"), tmp_path, until=2.0)
