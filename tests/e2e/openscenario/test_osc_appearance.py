"""AppearanceAction / LightStateAction on SUMO: a vehicle's lamps become SUMO's signal bits
(brake lights, indicators); AnimationAction is refused with its reason."""

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

from hiyari.bridge.openscenario.xosc.reader import read_scenario
from hiyari.errors import HiyariError


def _light(kind: str, mode: str) -> str:
    return f"""<AppearanceAction><LightStateAction><LightType><VehicleLight vehicleLightType="{kind}"/></LightType>
<LightState mode="{mode}"/></LightStateAction></AppearanceAction>"""


def test_lamps_become_sumo_signals(tmp_path: Path) -> None:
    stories = story("Car", _light("brakeLights", "on"), time_condition(0.99, "b"), "Brake")
    stories += story("Car", _light("indicatorLeft", "flashing"), time_condition(1.49, "l"), "Left")
    stories += story("Car", _light("brakeLights", "off"), time_condition(1.99, "o"), "Off")
    init = teleport_speed("Ego", -4, 20, 10) + teleport_speed("Car", -3, 100, 10)
    bits = {}

    def on_step(sim, world, report, engine) -> None:
        bits[round(report.time, 2)] = sim.signals("Car")

    run_scenario(
        write(tmp_path / "a.xosc", scenario_xml({"Ego": "", "Car": ""}, init, stories)),
        tmp_path,
        until=2.5,
        on_step=on_step,
    )
    assert bits[1.0] & 8 and not bits[1.0] & 2
    assert bits[1.5] & 8 and bits[1.5] & 2
    assert not bits[2.0] & 8 and bits[2.0] & 2


def test_animation_is_refused(tmp_path: Path) -> None:
    anim = """<AppearanceAction><AnimationAction><AnimationType><ComponentAnimation><VehicleComponent vehicleComponentType="doorFrontLeft"/>
</ComponentAnimation></AnimationType></AnimationAction></AppearanceAction>"""
    text = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -4, 20, 10),
        story("Car", anim, time_condition(1.0)),
    )
    with pytest.raises(HiyariError, match="rigid boxes with no animated parts"):
        read_scenario(write(tmp_path / "n.xosc", text))
