"""SpeedCondition, AccelerationCondition and RelativeSpeedCondition with a ``direction``
(longitudinal, lateral, vertical: the triggering entity's axes) on SUMO, on the ALKS road that
curves left with a 250 m radius: two scripted cars 80 m apart in lane -3 (t = -4.5 m, a
254.5 m radius) at 20 m/s along their path; the reference line's heading grows by 0.004 rad a
metre, so the cars' headings differ by 0.32 rad."""

from __future__ import annotations

from pathlib import Path

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
