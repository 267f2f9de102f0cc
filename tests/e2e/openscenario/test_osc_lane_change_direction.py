"""LaneChangeAction into a lane of the other driving direction (real SUMO): the actor moves
sideways and goes on the way it went (it drives against the lane, as when overtaking on a
two-lane road); it does not turn round with the lane."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from openscenario_files import scenario_xml, story, teleport_speed, time_condition, write

from hiyari.bridge.loop.execute import execute
from hiyari.bridge.loop.spec import EgoSetup, model_spec
from hiyari.bridge.openscenario.xosc.reader import read_scenario

DT = 0.05


def _car(lane: int, relative_h: float) -> str:
    """Car on road 0 (along +x) at s = 100 in ``lane``, turned ``relative_h`` from the lane's
    driving direction, at 10 m/s."""
    return f"""<Private entityRef="Car">
<PrivateAction><TeleportAction><Position><LanePosition roadId="0" laneId="{lane}" offset="0" s="100">
<Orientation type="relative" h="{relative_h}" p="0" r="0"/></LanePosition></Position></TeleportAction></PrivateAction>
<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="10"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>
</Private>"""


@pytest.mark.parametrize(
    ("start_lane", "relative_h", "target_lane", "y_end"),
    [
        (-3, 0.0, 3, 4.5),  # with its lane, out into the oncoming lane (aeb_cut_in)
        (3, np.pi, -3, -4.5),  # against its lane, back into a lane of its way (cut-in_simple)
    ],
)
def test_lane_change_across_the_centre_keeps_the_direction_of_travel(
    tmp_path: Path, start_lane: int, relative_h: float, target_lane: int, y_end: float
) -> None:
    """On the ALKS straight road (along +x; lanes -3 and 3 centred at t = -4.5 / +4.5 m) the
    Car drives +x at 10 m/s and, from t = 1 s, changes to ``target_lane`` (sinusoidal, 3 s).
    Its x grows every step; after the change (t = 4 s) it is on the target lane's centre and
    goes 10 m/s * 1.5 s = 15 m further +x from t = 4.5 to 6 s (before the fix it reversed at the end of
    the change and drove backwards)."""
    change = f"""<LateralAction><LaneChangeAction>
<LaneChangeActionDynamics dynamicsShape="sinusoidal" value="3" dynamicsDimension="time"/>
<LaneChangeTarget><AbsoluteTargetLane value="{target_lane}"/></LaneChangeTarget></LaneChangeAction></LateralAction>"""
    xml = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -5, 5.0, 0.0) + _car(start_lane, relative_h),
        story("Car", change, time_condition(1.0)),
        stop=f"<ConditionGroup>{time_condition(6.0, 'end', 'none')}</ConditionGroup>",
    )
    sc = read_scenario(write(tmp_path / "change.xosc", xml))
    xy: list[np.ndarray] = []
    res = execute(
        model_spec(sc, EgoSetup(perception="none")),
        on_step=lambda w, s, c: xy.append(w.xyz[w.index("Car"), :2].copy()),
    )
    assert res.stop_trigger and not res.collision
    p = np.array(xy)
    assert (np.diff(p[:, 0]) > 0.3).all()  # never slower than 6 m/s along +x, never back
    k4, k45, k6 = round(4.0 / DT), round(4.5 / DT), round(6.0 / DT)
    assert p[k6, 0] - p[k45, 0] == pytest.approx(15.0, abs=1e-6)
    assert p[k4 + 1 :, 1] == pytest.approx(y_end, abs=1e-6)
