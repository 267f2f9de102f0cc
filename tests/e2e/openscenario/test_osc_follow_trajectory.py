"""FollowTrajectoryAction without timing on SUMO: a scripted actor starts at the trajectory's
start plus initialDistanceOffset and moves along it at the speed its SpeedActions give
(followingMode follow: a scripted actor follows exactly); a stack-driven ego steers along its
trajectory at the stack's speed."""

from __future__ import annotations

import math
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

SPLINE = """<RoutingAction><FollowTrajectoryAction initialDistanceOffset="5"><TimeReference><None/></TimeReference>
<TrajectoryFollowingMode followingMode="follow"/><TrajectoryRef><Trajectory name="bend" closed="false"><Shape><ClothoidSpline>
<ClothoidSplineSegment curvatureStart="0" curvatureEnd="0" length="20"><PositionStart><WorldPosition x="100" y="-10" h="0"/></PositionStart></ClothoidSplineSegment>
<ClothoidSplineSegment curvatureStart="0.02" curvatureEnd="0.02" length="200"/></ClothoidSpline></Shape></Trajectory></TrajectoryRef>
</FollowTrajectoryAction></RoutingAction>"""
FASTER = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="rate" value="5"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="20"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def test_untimed_trajectory_at_the_speed_of_the_longitudinal_actions(tmp_path: Path) -> None:
    init = teleport_speed("Ego", -4, 20, 10) + teleport_speed("Car", -3, 60, 10)
    init += f'<Private entityRef="Car"><PrivateAction>{SPLINE}</PrivateAction></Private>'
    stories = story("Car", FASTER, time_condition(0.99, "go", "none"), "F")
    at = {}

    def on_step(sim, world, report, engine) -> None:
        car = engine.actors["Car"]  # the engine's state is a step ahead of the report
        at[round(report.time + 0.05, 2)] = (car.path.travelled, car.x, car.y, car.h)

    run_scenario(
        write(tmp_path / "t.xosc", scenario_xml({"Ego": "", "Car": ""}, init, stories)),
        tmp_path,
        until=4.0,
        on_step=on_step,
    )
    # 5 m offset, 10 m/s to 1 s, 10 -> 20 m/s over 2 s, then 20 m/s: 5 + 10 + 30 + 20 = 65 m at 4 s
    assert at[1.0][0] == pytest.approx(15.0) and at[4.0][0] == pytest.approx(65.0)
    # 45 m into the arc of radius 50 starting at (120, -10) heading +x
    phi = 45.0 / 50.0
    x, y, h = at[4.0][1:]
    assert (x, y) == pytest.approx(
        (120 + 50 * math.sin(phi), -10 + 50 * (1 - math.cos(phi))), abs=1e-4
    )
    assert h == pytest.approx(phi, abs=1e-9)


def test_stack_driven_ego_steers_along_its_trajectory(tmp_path: Path) -> None:
    ego_traj = """<PrivateAction><RoutingAction><FollowTrajectoryAction><TimeReference><None/></TimeReference>
<TrajectoryFollowingMode followingMode="follow"/><TrajectoryRef><Trajectory name="diag" closed="false"><Shape><Polyline>
<Vertex><Position><WorldPosition x="30" y="-12" h="0.6435011087932844"/></Position></Vertex>
<Vertex><Position><WorldPosition x="70" y="18" h="0.6435011087932844"/></Position></Vertex></Polyline></Shape></Trajectory>
</TrajectoryRef></FollowTrajectoryAction></RoutingAction></PrivateAction>"""
    init = teleport_speed("Ego", -4, 20, 10).replace("</Private>", ego_traj + "</Private>")
    poses = {}

    def on_step(sim, world, report, engine) -> None:
        k = world.index("Ego")
        poses[round(report.time, 2)] = (*world.xyz[k, :2], float(world.heading[k]))

    run_scenario(
        write(tmp_path / "e.xosc", scenario_xml({"Ego": ""}, init)),
        tmp_path,
        until=2.5,
        on_step=on_step,
    )
    # the stand-in holds 10 m/s: 20 m along the 3-4-5 diagonal at 2 s, box centre 1.4 m ahead
    c, s = 0.8, 0.6
    x, y, h = poses[2.0]
    assert (x, y) == pytest.approx((30 + 20 * c + 1.4 * c, -12 + 20 * s + 1.4 * s), abs=1e-3)
    assert h == pytest.approx(math.atan2(s, c), abs=1e-6)


TIMED = """<RoutingAction><FollowTrajectoryAction><TimeReference><Timing domainAbsoluteRelative="absolute" scale="1" offset="0"/></TimeReference>
<TrajectoryFollowingMode followingMode="position"/><TrajectoryRef><Trajectory name="walk" closed="false"><Shape><Polyline>
<Vertex time="1.0"><Position><WorldPosition x="100" y="{y}" h="0"/></Position></Vertex>
<Vertex time="5.02"><Position><WorldPosition x="110.05" y="{y}" h="0"/></Position></Vertex></Polyline></Shape></Trajectory>
</TrajectoryRef></FollowTrajectoryAction></RoutingAction>"""


@pytest.mark.parametrize("y", [40.0, 0.0], ids=["off_road", "on_road"])
def test_timed_trajectory_end_keeps_the_speed(tmp_path: Path, y: float) -> None:
    """10.05 m in 4.02 s: 2.5 m/s from (100, y) at 1 s. The trajectory ends at 5.02 s, inside
    a step; the action ends, the actor does not stop: it goes on at 2.5 m/s (straight ahead
    off the road, along its lane on it), so x = 100 + 2.5 (t - 1) at every step, before and
    after the end. (It stopped dead at the end: 2.5 -> 0 m/s in one step.)"""
    init = teleport_speed("Ego", -4, 20, 10) + teleport_speed("Car", -3, 60, 0)
    init += f'<Private entityRef="Car"><PrivateAction>{TIMED.format(y=y)}</PrivateAction></Private>'
    at = {}

    def on_step(sim, world, report, engine) -> None:
        car = engine.actors["Car"]  # the engine's state is a step ahead of the report
        at[round(report.time + 0.05, 2)] = (car.x, car.v)

    run_scenario(
        write(tmp_path / "t.xosc", scenario_xml({"Ego": "", "Car": ""}, init)),
        tmp_path,
        until=7.0,
        on_step=on_step,
    )
    for t in (2.0, 5.0, 5.05, 5.5, 6.0):
        x, v = at[t]
        assert v == pytest.approx(2.5, abs=1e-9), t
        assert x == pytest.approx(100 + 2.5 * (t - 1), abs=1e-6), t
