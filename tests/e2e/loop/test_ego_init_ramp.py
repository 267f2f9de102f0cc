"""A stack-driven ego whose Init SpeedAction has a transition (not a step): its stack keeps the
action's target, and the ego ramps to it as the transition says (real SUMO, hiyari's stack)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from openscenario_files import scenario_xml, teleport_speed, time_condition, write

from hiyari.bridge.loop.execute import execute
from hiyari.bridge.loop.spec import EgoSetup, StackContext, default_stack, model_spec
from hiyari.bridge.openscenario.xosc.reader import read_scenario

DT = 0.05


def _ramp_init(dynamics: str, target: str) -> str:
    """Ego Init: on lane -4 at s = 5 (standing), then a SpeedAction with ``dynamics``."""
    return f"""<Private entityRef="Ego">
<PrivateAction><TeleportAction><Position><LanePosition roadId="0" laneId="-4" offset="0" s="5"/></Position></TeleportAction></PrivateAction>
<PrivateAction><LongitudinalAction><SpeedAction>{dynamics}
<SpeedActionTarget>{target}</SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>
</Private>"""


def _run(tmp_path: Path, init: str, entities: dict[str, str]) -> tuple[list[float], np.ndarray]:
    xml = scenario_xml(
        entities,
        init,
        stop=f"<ConditionGroup>{time_condition(6.0, 'end', 'none')}</ConditionGroup>",
    )
    sc = read_scenario(write(tmp_path / "ramp.xosc", xml))
    made: list[StackContext] = []

    def factory(ctx: StackContext):  # noqa: ANN202 - the factory protocol
        made.append(ctx)
        return default_stack(ctx)

    res = execute(model_spec(sc, EgoSetup(stack=factory, perception="none")))
    assert res.stop_trigger and not res.collision
    return [c.set_speed for c in made], np.asarray(res.series.ego_speed)


def test_linear_rate_ramp_to_an_absolute_target(tmp_path: Path) -> None:
    """linear, rate 5 m/s^2, 0 -> 20 m/s: set speed 20 (was 0: the ego stood for the whole run);
    the k-th scored state (scenario time k dt) has v = min(5 k dt, 20): 20 from t = 4 s, and the
    ACC holds it."""
    dyn = '<SpeedActionDynamics dynamicsShape="linear" value="5" dynamicsDimension="rate"/>'
    init = _ramp_init(dyn, '<AbsoluteTargetSpeed value="20"/>')
    set_speeds, v = _run(tmp_path, init, {"Ego": ""})
    assert set_speeds == [20.0]
    k = np.arange(len(v))
    assert v == pytest.approx(np.minimum(5.0 * k * DT, 20.0), abs=1e-6)
    assert len(v) == round(6.0 / DT) + 1  # t = 0 (the Init state) .. 6 s


def test_cubic_time_ramp_to_a_relative_target(tmp_path: Path) -> None:
    """cubic over 4 s to the Lead's Init speed (15 m/s, placed first) + 5 = 20 m/s: at t = 2 s
    the ego is half-way (cubic 3x^2 - 2x^3 at x = 0.5: 0.5, 10 m/s), at t = 1 s 20 * 0.15625
    = 3.125 m/s, from 4 s at 20."""
    dyn = '<SpeedActionDynamics dynamicsShape="cubic" value="4" dynamicsDimension="time"/>'
    rel = (
        '<RelativeTargetSpeed entityRef="Lead" value="5" speedTargetValueType="delta" '
        'continuous="false"/>'
    )
    init = teleport_speed("Lead", -3, 200.0, 15.0) + _ramp_init(dyn, rel)
    set_speeds, v = _run(tmp_path, init, {"Ego": "", "Lead": ""})
    assert set_speeds == [20.0]
    assert v[0] == pytest.approx(0.0, abs=1e-9)
    assert v[20] == pytest.approx(3.125, abs=1e-6)
    assert v[40] == pytest.approx(10.0, abs=1e-6)
    assert v[80:] == pytest.approx(20.0, abs=1e-6)
