"""Distances in trajectory coordinates (coordinateSystem="trajectory": along and across the
trajectory the triggering entity follows) on SUMO: Car follows a straight polyline from
(50, -8) to (90, 22) (direction (0.8, 0.6)) at 10 m/s; Ref stands at (90, -8) facing along
it: 32 m along the trajectory, 24 m to its right. A condition in trajectory coordinates on
an entity given no trajectory is refused with the file and line."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from openscenario_files import run_scenario, scenario_xml, story, teleport_speed, write

from hiyari.errors import HiyariError

FOLLOW = """<RoutingAction><FollowTrajectoryAction initialDistanceOffset="0">
<TrajectoryRef><Trajectory name="Diagonal" closed="false"><Shape><Polyline>
<Vertex><Position><WorldPosition x="50" y="-8"/></Position></Vertex>
<Vertex><Position><WorldPosition x="90" y="22"/></Position></Vertex>
</Polyline></Shape></Trajectory></TrajectoryRef>
<TimeReference><None/></TimeReference><TrajectoryFollowingMode followingMode="position"/>
</FollowTrajectoryAction></RoutingAction>"""
REF = f"""<Private entityRef="Ref">
<PrivateAction><TeleportAction><Position><WorldPosition x="90" y="-8" h="{math.atan2(0.6, 0.8)}"/></Position></TeleportAction></PrivateAction>
</Private>"""


def _condition(name: str, kind: str, value: float, rule: str, fs: str, who: str = "Car") -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="{who}"/></TriggeringEntities>
<EntityCondition><RelativeDistanceCondition entityRef="Ref" relativeDistanceType="{kind}" value="{value}"
freespace="{fs}" rule="{rule}" coordinateSystem="trajectory"/></EntityCondition></ByEntityCondition></Condition>"""


HOLD = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="10"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""
#: (name, conditions (ANDed), whether it ever holds): 24 m across between the reference
#: points, 24 - 1 - 1 = 22 m between the 2 m wide boxes.
CASES = [
    ("Lat", _condition("a", "lateral", 24.001, "lessThan", "false")
     + _condition("b", "lateral", 23.999, "greaterThan", "false"), True),
    ("LatFar", _condition("c", "lateral", 24.001, "greaterThan", "false"), False),
    ("Free", _condition("d", "lateral", 22.001, "lessThan", "true")
     + _condition("e", "lateral", 21.999, "greaterThan", "true"), True),
    ("Near", _condition("f", "longitudinal", 1.0, "lessThan", "false"), True),
]  # fmt: skip


def _xml(cases: list[tuple[str, str, bool]]) -> str:
    init = teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -4, 50, 10) + REF
    go = """<Condition name="go" delay="0" conditionEdge="none"><ByValueCondition>
<SimulationTimeCondition value="0" rule="greaterOrEqual"/></ByValueCondition></Condition>"""
    stories = story("Car", FOLLOW, go, "F")
    stories += "".join(story("Car", HOLD, conds, name) for name, conds, _ in cases)
    return scenario_xml({"Ego": "", "Car": "", "Ref": ""}, init, stories)


def test_distances_along_and_across_the_trajectory(tmp_path: Path) -> None:
    engine, _ = run_scenario(write(tmp_path / "t.xosc", _xml(CASES)), tmp_path, until=4.0)
    started = {n: t for t, _, n, tr in engine.tree.log if tr == "startTransition"}
    for name, _, fires in CASES:
        assert (name + "Action" in started) == fires, name
    # within 1 m of Ref's 32 m along the trajectory after 31 m at 10 m/s: 3.1 s
    assert started["NearAction"] - started["FAction"] == pytest.approx(3.1, abs=0.06)


def test_trajectory_frame_without_a_trajectory_is_refused(tmp_path: Path) -> None:
    bad = [("Ego", _condition("g", "lateral", 1.0, "lessThan", "false", "Ego"), False)]
    path = write(tmp_path / "n.xosc", _xml(bad))
    pattern = re.escape(str(path)) + r":\d+: coordinateSystem trajectory, but 'Ego' is given no"
    with pytest.raises(HiyariError, match=pattern):
        run_scenario(path, tmp_path, until=0.1)
