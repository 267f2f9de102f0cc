"""Distances and headways in lane coordinates (coordinateSystem="lane": along the centre line
of the triggering entity's lane, laterally in lanes) and road distances between reference
points, on SUMO on the ALKS road that curves left with a 250 m radius. Car and Ref drive
lane -3 (t = -4.5 m: a 254.5 m radius) 80 m of road s apart at 20 m/s along their path, so
the lane's centre line between them is 80 x 254.5 / 250 = 81.44 m long; Side, a car whose
box is centred on its reference point, drives lane -4 at the same s as Ref."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    CAR,
    ROADS,
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.errors import HiyariError

CURVE = ROADS / "alks_road_left_radius_250m.xodr"
HOLD = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="20"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def _distance(ref: str, kind: str, value: float, rule: str, frame: str, fs: str = "false") -> str:
    return (
        f'<RelativeDistanceCondition entityRef="{ref}" relativeDistanceType="{kind}" '
        f'value="{value}" freespace="{fs}" rule="{rule}" coordinateSystem="{frame}"/>'
    )


#: (name, condition body, whether it ever holds in the first second). Car's box reaches
#: 3.9 m ahead of its reference point and 1.1 m behind; Side's reference point is its box's
#: centre, 1.4 m behind where a CAR's box centre would be.
CASES = [
    ("LaneLon", _distance("Ref", "longitudinal", 81.43, "greaterThan", "lane"), True),
    ("LaneLonTooFar", _distance("Ref", "longitudinal", 81.45, "greaterThan", "lane"), False),
    ("RoadLon", _distance("Ref", "longitudinal", 80.001, "lessThan", "road"), True),
    ("RoadLonFar", _distance("Ref", "longitudinal", 80.001, "greaterThan", "road"), False),
    # freespace: 81.44 - 3.9 - 1.1 = 76.44 m
    ("LaneFree", _distance("Ref", "longitudinal", 76.43, "greaterThan", "lane", "true"), True),
    ("LaneFreeFar", _distance("Ref", "longitudinal", 76.45, "greaterThan", "lane", "true"), False),
    ("LaneLat", _distance("Side", "lateral", 1, "equalTo", "lane"), True),
    ("RoadLat", _distance("Side", "lateral", 3.5, "equalTo", "road"), True),
    # reference points 80 m of road s apart at the start (the box centres: 78.6 m); Side's
    # s grows more slowly in the outer lane (0.27 m less a second)
    ("RoadRefs", _distance("Side", "longitudinal", 79.5, "lessThan", "road"), False),
    ("RoadRefsNear", _distance("Side", "longitudinal", 80.001, "lessThan", "road"), True),
    # headway: 81.44 m / 20 m/s = 4.072 s
    ("Headway", '<TimeHeadwayCondition entityRef="Ref" value="4.07" freespace="false" rule="greaterThan" coordinateSystem="lane" relativeDistanceType="longitudinal"/>', True),
    ("HeadwayLong", '<TimeHeadwayCondition entityRef="Ref" value="4.075" freespace="false" rule="greaterThan" coordinateSystem="lane" relativeDistanceType="longitudinal"/>', False),
    # to a lane position 200 m of s ahead of the start: 203.6 m of lane centre, less after
    ("Point", '<DistanceCondition value="203.6" freespace="false" rule="lessThan" coordinateSystem="lane" relativeDistanceType="longitudinal"><Position><LanePosition roadId="0" laneId="-3" offset="0" s="300"/></Position></DistanceCondition>', True),
    ("PointFar", '<DistanceCondition value="203.65" freespace="false" rule="greaterThan" coordinateSystem="lane" relativeDistanceType="longitudinal"><Position><LanePosition roadId="0" laneId="-3" offset="0" s="300"/></Position></DistanceCondition>', False),
]  # fmt: skip


def _entity_condition(name: str, body: str) -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Car"/></TriggeringEntities>
<EntityCondition>{body}</EntityCondition></ByEntityCondition></Condition>"""


def _xml(cases: list[tuple[str, str, bool]]) -> str:
    init = (
        teleport_speed("Ego", -4, 20, 20)
        + teleport_speed("Car", -3, 100, 20)
        + teleport_speed("Ref", -3, 180, 20)
        + teleport_speed("Side", -4, 180, 20)
    )
    stories = "".join(
        story("Car", HOLD, _entity_condition(name + "C", body), name) for name, body, _ in cases
    )
    stop = f"<ConditionGroup>{time_condition(1.0, 'end')}</ConditionGroup>"
    side = CAR.format(name="Side").replace('x="1.4"', 'x="0.0"')
    entities = {"Ego": "", "Car": "", "Ref": "", "Side": side}
    return scenario_xml(entities, init, stories, stop, road=CURVE)


def test_lane_and_road_distances(tmp_path: Path) -> None:
    engine, _ = run_scenario(write(tmp_path / "l.xosc", _xml(CASES)), tmp_path, until=1.5)
    started = {n for _, _, n, tr in engine.tree.log if tr == "startTransition"}
    for name, _, fires in CASES:
        assert (name + "Action" in started) == fires, name


def test_lateral_time_to_collision_in_lanes_is_refused(tmp_path: Path) -> None:
    from hiyari.bridge.openscenario.xosc.reader import read_scenario

    ttc = """<TimeToCollisionCondition value="2" freespace="false" rule="lessThan" coordinateSystem="lane"
relativeDistanceType="lateral"><TimeToCollisionConditionTarget><EntityRef entityRef="Ref"/></TimeToCollisionConditionTarget></TimeToCollisionCondition>"""
    path = write(tmp_path / "t.xosc", _xml([("Ttc", ttc, False)]))
    with pytest.raises(HiyariError, match=r"t\.xosc:\d+: .*lateral time to collision in lanes"):
        read_scenario(path)
