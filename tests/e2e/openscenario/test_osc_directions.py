"""SpeedCondition, AccelerationCondition and RelativeSpeedCondition with a ``direction``
(longitudinal, lateral, vertical: the triggering entity's axes) on SUMO, on the ALKS road that
curves left with a 250 m radius: two scripted cars 80 m apart in lane -3 (t = -4.5 m, a
254.5 m radius) at 20 m/s along their path; the reference line's heading grows by 0.004 rad a
metre, so the cars' headings differ by 0.32 rad."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    ROADS,
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

CURVE = ROADS / "alks_road_left_radius_250m.xodr"
#: A no-op for an event to run: the car's own speed, at once.
HOLD = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="20"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def _entity_condition(name: str, body: str) -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Car"/></TriggeringEntities>
<EntityCondition>{body}</EntityCondition></ByEntityCondition></Condition>"""


#: (story name, condition body, whether it ever holds). Hand-derived values:
#: lateral acceleration v^2 / r = 400 / 254.5 = 1.5717 m/s^2 (to the left);
#: relative velocity Car - Ref in Car's axes: (20 - 20 cos 0.32, -20 sin 0.32)
#: = (1.0152, -6.2915) m/s; own lateral and vertical speeds, vertical acceleration: 0.
CASES = [
    ("LatAccAbove", '<AccelerationCondition value="1.565" rule="greaterThan" direction="lateral"/>', True),
    ("LatAccBelow", '<AccelerationCondition value="1.578" rule="lessThan" direction="lateral"/>', True),
    ("LatAccTooBig", '<AccelerationCondition value="1.578" rule="greaterThan" direction="lateral"/>', False),
    ("VertAcc", '<AccelerationCondition value="0" rule="equalTo" direction="vertical"/>', True),
    ("LonAcc", '<AccelerationCondition value="0" rule="equalTo" direction="longitudinal"/>', True),
    ("LatSpeed", '<SpeedCondition value="0" rule="equalTo" direction="lateral"/>', True),
    ("VertSpeed", '<SpeedCondition value="0" rule="equalTo" direction="vertical"/>', True),
    ("LonSpeed", '<SpeedCondition value="19.999" rule="greaterThan" direction="longitudinal"/>', True),
    ("RelLat", '<RelativeSpeedCondition entityRef="Ref" value="-6.285" rule="lessThan" direction="lateral"/>', True),
    ("RelLatTooBig", '<RelativeSpeedCondition entityRef="Ref" value="-6.298" rule="lessThan" direction="lateral"/>', False),
    ("RelLon", '<RelativeSpeedCondition entityRef="Ref" value="1.01" rule="greaterThan" direction="longitudinal"/>', True),
    ("RelLonTooBig", '<RelativeSpeedCondition entityRef="Ref" value="1.02" rule="greaterThan" direction="longitudinal"/>', False),
    ("RelNone", '<RelativeSpeedCondition entityRef="Ref" value="0" rule="equalTo"/>', True),
    ("RelVert", '<RelativeSpeedCondition entityRef="Ref" value="0" rule="equalTo" direction="vertical"/>', True),
]  # fmt: skip


def test_directional_speeds_and_accelerations(tmp_path: Path) -> None:
    init = (
        teleport_speed("Ego", -4, 20, 20)
        + teleport_speed("Car", -3, 100, 20)
        + teleport_speed("Ref", -3, 180, 20)
    )
    stories = "".join(
        story("Car", HOLD, _entity_condition(name + "C", body), name) for name, body, _ in CASES
    )
    stop = f"<ConditionGroup>{time_condition(1.0, 'end')}</ConditionGroup>"
    xml = scenario_xml({"Ego": "", "Car": "", "Ref": ""}, init, stories, stop, road=CURVE)
    engine, _ = run_scenario(write(tmp_path / "d.xosc", xml), tmp_path, until=1.5)
    started = {n for _, _, n, tr in engine.tree.log if tr == "startTransition"}
    for name, _, fires in CASES:
        assert (name + "Action" in started) == fires, name


#: From 10 m/s to -6 m/s (reversing) at 4 m/s^2, started at t = 0.05 (the first step; the
#: speed changes from there): v(t) = 10 - 4 (t - 0.05), -5.9 at t = 4.025, -6 from t = 4.05.
REVERSE = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="rate" value="4"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="-6"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""

#: (story name, condition body, from time (s), expected start (s)). With no direction the
#: total speed |v| and the total acceleration |a| (the standard's "total"), never negative;
#: with longitudinal the signed components. |a| = 4 m/s^2 over the steps the speed changes
#: in (measured from t = 0.1: the first measure, at 0.05, has no yaw rate yet), 0 from the
#: step after t = 4.05; |v| > 5.9 and v < -5.9 from the first step after t = 4.025; while
#: reversing (v < 0 from t = 2.55) the longitudinal acceleration stays -4 (SUMO's is d|v|/dt).
TOTALS = [
    ("TotAcc", '<AccelerationCondition value="3.9" rule="greaterThan"/>', 0.0, 0.1),
    ("LonAcc", '<AccelerationCondition value="-3.9" rule="lessThan" direction="longitudinal"/>', 0.0, 0.1),
    ("TotAccZero", '<AccelerationCondition value="0.01" rule="lessThan"/>', 1.0, 4.1),
    ("TotSpeed", '<SpeedCondition value="5.9" rule="greaterThan"/>', 3.0, 4.05),
    ("LonSpeed", '<SpeedCondition value="-5.9" rule="lessThan" direction="longitudinal"/>', 3.0, 4.05),
    ("LonAccBack", '<AccelerationCondition value="-3.9" rule="lessThan" direction="longitudinal"/>', 3.0, 3.0),
]  # fmt: skip


def test_total_speed_and_acceleration_without_direction(tmp_path: Path) -> None:
    # the events act on a third car (holding its speed), not on the measured one
    init = (
        teleport_speed("Ego", -1, 20, 20)
        + teleport_speed("Car", -1, 200, 10)
        + teleport_speed("Obs", -2, 300, 20)
    )
    stories = story("Car", REVERSE, time_condition(0.0, "go", "none"), "Go")
    for name, body, after, _ in TOTALS:
        when = time_condition(after, name + "T", "none") + _entity_condition(name + "C", body)
        stories += story("Obs", HOLD, when, name)
    stop = f"<ConditionGroup>{time_condition(5.0, 'end')}</ConditionGroup>"
    xml = scenario_xml({"Ego": "", "Car": "", "Obs": ""}, init, stories, stop)
    engine, _ = run_scenario(write(tmp_path / "t.xosc", xml), tmp_path, until=5.5)
    started = {n: t for t, _, n, tr in engine.tree.log if tr == "startTransition"}
    for name, _, _, expected in TOTALS:
        assert started.get(name + "Action") == pytest.approx(expected), name
