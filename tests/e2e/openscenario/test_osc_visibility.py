"""VisibilityAction in the closed loop: a standing car hidden from the ego's sensors is not
braked for (the ego hits it), the same car seen is; traffic = false and sensor references are
refused with their reasons."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import net_for, scenario_xml, teleport_speed, write

from hiyari.bridge.loop.execute import execute
from hiyari.bridge.loop.spec import EgoSetup, model_spec
from hiyari.bridge.openscenario.xosc.reader import read_scenario
from hiyari.errors import HiyariError


def _visibility(sensors: str, traffic: str = "true") -> str:
    return f'<PrivateAction><VisibilityAction graphics="true" traffic="{traffic}" sensors="{sensors}"/></PrivateAction>'


def _run(tmp_path: Path, sensors: str) -> object:
    car = teleport_speed("Car", -4, 120, 0).replace(
        "</Private>", _visibility(sensors) + "</Private>"
    )
    init = teleport_speed("Ego", -4, 20, 15) + car
    path = write(tmp_path / f"v_{sensors}.xosc", scenario_xml({"Ego": "", "Car": ""}, init))
    sc = read_scenario(path)
    return execute(model_spec(sc, EgoSetup(max_duration=12.0), net_for(sc.road_network, tmp_path)))


def test_an_entity_hidden_from_the_sensors_is_not_braked_for(tmp_path: Path) -> None:
    seen, hidden = _run(tmp_path, "true"), _run(tmp_path, "false")
    assert not seen.collision
    assert (
        hidden.collision
        and hidden.collided_with == "Car"
        and hidden.impact_speed == pytest.approx(15.0, abs=0.01)
    )


def test_traffic_false_is_refused(tmp_path: Path) -> None:
    init = teleport_speed("Ego", -4, 20, 15).replace(
        "</Private>", _visibility("true", "false") + "</Private>"
    )
    with pytest.raises(HiyariError, match="traffic = false: SUMO's own traffic always sees"):
        read_scenario(write(tmp_path / "t.xosc", scenario_xml({"Ego": ""}, init)))
