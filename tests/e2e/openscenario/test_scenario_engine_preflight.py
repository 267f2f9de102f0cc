"""The engine refuses at start (before the first step) a story SpeedAction whose failure the
Init state already decides, with the run's own message, and leaves to the run every action
whose start speed it cannot know (engine.preflight). Real SUMO, small files."""

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

from hiyari.errors import HiyariError


def _speed(value: float, rate: float = 0.0, relative_to: str = "") -> str:
    target = (
        f'<RelativeTargetSpeed entityRef="{relative_to}" value="{value}" '
        'speedTargetValueType="delta" continuous="false"/>'
        if relative_to
        else f'<AbsoluteTargetSpeed value="{value}"/>'
    )
    return (
        '<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="linear" '
        f'dynamicsDimension="rate" value="{rate}"/><SpeedActionTarget>{target}'
        "</SpeedActionTarget></SpeedAction></LongitudinalAction>"
    )


def _file(tmp_path: Path, stories: str, car_speed: float = 10.0) -> tuple[Path, str]:
    init = (
        teleport_speed("Ego", -4, 5.0, 10.0)
        + teleport_speed("Car", -5, 30.0, car_speed)
        + teleport_speed("Lead", -5, 80.0, 10.0)
    )
    xml = scenario_xml({"Ego": "", "Car": "", "Lead": ""}, init, stories)
    return write(tmp_path / "s.xosc", xml), xml


def test_a_rate_of_zero_to_another_speed_is_refused_at_start(tmp_path: Path) -> None:
    path, xml = _file(tmp_path, story("Car", _speed(20.0), time_condition(1.0)))
    line = xml[: xml.index('value="0.0"/><SpeedActionTarget>')].count("\n") + 1
    steps = []
    with pytest.raises(HiyariError) as err:
        run_scenario(path, tmp_path, until=3.0, on_step=lambda *a: steps.append(a))
    assert str(err.value) == (
        f"{path}:{line}: SpeedAction: transition rate value must be positive, got 0"
    )
    assert steps == []  # refused before the first step


def test_relative_target_to_a_steady_entity_is_checked(tmp_path: Path) -> None:
    # Lead keeps 10 m/s; the Car at 15 m/s is to reach Lead + 0 = 10 m/s at a rate of 0
    path, _ = _file(
        tmp_path, story("Car", _speed(0.0, relative_to="Lead"), time_condition(1.0)), 15.0
    )
    steps = []
    with pytest.raises(HiyariError, match="transition rate value must be positive"):
        run_scenario(path, tmp_path, until=3.0, on_step=lambda *a: steps.append(a))
    assert steps == []  # refused before the first step


@pytest.mark.parametrize(
    "stories, car_speed, end_speed",
    [
        # already at the target: nothing to change, the rate does not matter
        (lambda: story("Car", _speed(10.0), time_condition(1.0)), 10.0, 10.0),
        # an earlier action sets the speed the rate-0 action starts from: left to the run,
        # which reaches 20 m/s at 1 s and then has nothing to change
        (
            lambda: (
                story("Car", _speed(20.0, rate=100.0), time_condition(1.0), "A")
                + story("Car", _speed(20.0), time_condition(2.0), "B")
            ),
            10.0,
            20.0,
        ),
    ],
)
def test_what_init_does_not_decide_is_left_to_the_run(
    tmp_path: Path, stories, car_speed: float, end_speed: float
) -> None:  # noqa: ANN001
    path, _ = _file(tmp_path, stories(), car_speed)
    engine, report = run_scenario(path, tmp_path, until=3.0)
    assert report.time == pytest.approx(3.0 - 0.05, abs=0.06)
    assert engine.actors["Car"].v == pytest.approx(end_speed)


def test_relative_to_the_stack_driven_ego_is_left_to_the_run(tmp_path: Path) -> None:
    """The stack decides the ego's speed: the action is judged when it starts (at 1 s)."""
    path, _ = _file(
        tmp_path, story("Car", _speed(0.0, relative_to="Ego"), time_condition(1.0)), 15.0
    )
    times = []
    with pytest.raises(HiyariError, match="transition rate value must be positive"):
        run_scenario(path, tmp_path, until=3.0, on_step=lambda s, w, r, e: times.append(r.time))
    assert times[-1] == pytest.approx(1.0 - 0.05, abs=0.06)
