"""AngleCondition and RelativeAngleCondition on SUMO: a car driving a circular arc of radius
50 m at 10 m/s has turned a right angle after 7.854 s; the conditions (tolerance 0.02 rad)
hold from the first step within it, in the world, against the road and against the ego."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from openscenario_files import run_scenario, scenario_xml, story, teleport_speed, write

ARC = """<RoutingAction><FollowTrajectoryAction><TimeReference><None/></TimeReference>
<TrajectoryFollowingMode followingMode="position"/><TrajectoryRef><Trajectory name="arc" closed="false"><Shape><ClothoidSpline>
<ClothoidSplineSegment curvatureStart="0.02" curvatureEnd="0.02" length="200"/></ClothoidSpline></Shape></Trajectory></TrajectoryRef>
</FollowTrajectoryAction></RoutingAction>"""
NOOP = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="10"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def _cond(name: str, inner: str) -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="rising"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Car"/></TriggeringEntities>
<EntityCondition>{inner}</EntityCondition></ByEntityCondition></Condition>"""


def test_angles_of_a_car_on_an_arc(tmp_path: Path) -> None:
    q = math.pi / 2
    init = teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -3, 50, 10)
    init += f'<Private entityRef="Car"><PrivateAction>{ARC}</PrivateAction></Private>'
    stories = story(
        "Car",
        NOOP,
        _cond("w", f'<AngleCondition angleType="heading" angle="{q}" angleTolerance="0.02"/>'),
        "World",
    )
    stories += story(
        "Car",
        NOOP,
        _cond(
            "r",
            f'<AngleCondition angleType="heading" angle="{q}" angleTolerance="0.02" coordinateSystem="road"/>',
        ),
        "Road",
    )
    stories += story(
        "Car",
        NOOP,
        _cond(
            "e",
            f'<RelativeAngleCondition entityRef="Ego" angleType="heading" angle="{q}" angleTolerance="0.02"/>',
        ),
        "Rel",
    )
    engine, _ = run_scenario(
        write(tmp_path / "a.xosc", scenario_xml({"Ego": "", "Car": ""}, init, stories)),
        tmp_path,
        until=9.0,
    )
    started = {
        n: t for t, kind, n, tr in engine.tree.log if kind == "event" and tr == "startTransition"
    }
    # turned q - 0.02 after 50 (q - 0.02) m: 7.754 s; the first update after is 7.8 s, and the
    # event starts at the update its condition holds
    first = math.ceil(50 * (q - 0.02) / 10 / 0.05 - 1e-9) * 0.05
    for name in ("WorldE", "RoadE", "RelE"):
        assert started[name] == pytest.approx(first)
