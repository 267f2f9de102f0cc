"""Routes along the roads of an OpenDRIVE junction (the Euro NCAP X intersection of
../shared): the road graph's shortest way, RoutePosition in the route's own coordinates (lane
ids and offsets counting in its direction of travel) and an actor following AssignRouteAction
through the junction on SUMO at its own speed."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from openscenario_files import SHARED, run_scenario, scenario_xml, teleport_speed, write

from hiyari.bridge.openscenario.engine.positions import PoseResolver
from hiyari.bridge.openscenario.model.positions import LanePosition, RoutePosition
from hiyari.bridge.openscenario.model.trajectories import Route
from hiyari.errors import HiyariError
from hiyari.net.road.opendrive_lanes import OpenDriveMap
from hiyari.net.road.topology import Leg, RoadGraph

XODR = SHARED / "ncap" / "OpenDRIVE" / "NCAP" / "X-Intersection_NCAP.xodr"
#: south arm (road 3, northbound) through the junction to the north arm (road 1, southbound s)
NORTH = Route("north", (LanePosition("3", -1, 0.0), LanePosition("1", 1, 0.0)))


def test_shortest_way_through_the_junction() -> None:
    g = RoadGraph.from_file(XODR)
    legs = g.route(("3", 10.0, 1), ("1", 0.0, -1))
    assert legs == [
        Leg("3", 1, 10.0, 250.0),
        Leg("9", 1, 0.0, 23.000000000000004),
        Leg("1", -1, 250.0, 0.0),
    ]
    # turning left from the west arm (road 0) to the north arm: the 18.06 m arc, road 4
    assert [x.road for x in g.route(("0", 200.0, 1), ("1", 100.0, -1))] == ["0", "4", "1"]
    with pytest.raises(HiyariError, match="no road connects"):
        g.route(("0", 10.0, 1), ("0", 5.0, 1))  # behind, one way: no turning on the spot


def test_route_position_counts_lanes_in_the_direction_of_travel() -> None:
    odr = OpenDriveMap.from_file(XODR)
    r = PoseResolver(odr, lambda name: None)
    assert r.route(NORTH).length == pytest.approx(523.0)
    # 30 m past the junction on road 1, driven against its s: lane -1 of the route is lane 1
    p = r.resolve(RoutePosition(NORTH, 303.0, lane=-1, lane_offset=0.5))
    assert (p.road, p.lane, p.s) == ("1", 1, pytest.approx(220.0))
    assert (p.x, p.y) == pytest.approx((261.5 + 1.75 - 0.5, 11.5 + 30.0))  # left: west
    assert p.h == pytest.approx(math.pi / 2)  # northbound, the way the route goes
    q = r.resolve(RoutePosition(NORTH, 261.5, t=-2.0))  # the junction's middle, 2 m right
    assert (q.x, q.y, q.road) == pytest.approx((263.5, 0.0, "9"))


def test_actor_follows_its_route_through_the_junction(tmp_path: Path) -> None:
    bike = """<Vehicle name="b" vehicleCategory="bicycle"><BoundingBox><Center x="0.5" y="0" z="0.9"/>
<Dimensions width="0.6" length="1.8" height="1.8"/></BoundingBox><Performance maxSpeed="15" maxDeceleration="5" maxAcceleration="5"/>
<Axles><FrontAxle maxSteering="0.5" wheelDiameter="0.7" trackWidth="0.1" positionX="1.1" positionZ="0.35"/>
<RearAxle maxSteering="0" wheelDiameter="0.7" trackWidth="0.1" positionX="0" positionZ="0.35"/></Axles><Properties/></Vehicle>"""
    route = """<Route name="north" closed="false">
<Waypoint routeStrategy="shortest"><Position><LanePosition roadId="3" laneId="-1" s="0"/></Position></Waypoint>
<Waypoint routeStrategy="shortest"><Position><LanePosition roadId="1" laneId="1" s="0"/></Position></Waypoint></Route>"""
    init = teleport_speed("Ego", -1, 50, 10).replace('roadId="0"', 'roadId="0"')
    init += f"""<Private entityRef="Bike">
<PrivateAction><TeleportAction><Position><LanePosition roadId="3" laneId="-1" s="240" offset="0.5"/></Position></TeleportAction></PrivateAction>
<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="5"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>
<PrivateAction><RoutingAction><AssignRouteAction>{route}</AssignRouteAction></RoutingAction></PrivateAction></Private>"""
    text = scenario_xml({"Ego": "", "Bike": bike}, init, road=XODR)
    seen: dict[float, tuple[float, float, float]] = {}

    def on_step(sim, world, report, engine) -> None:
        b = engine.actors["Bike"]
        seen[round(report.time + 0.05, 2)] = (b.x, b.y, b.h)  # the engine's state is a step ahead

    run_scenario(write(tmp_path / "r.xosc", text), tmp_path, until=6.0, on_step=on_step)
    # 5 m/s: at 2 s on road 3 (s = 250) at its lane offset, at 6 s 20 m into road 9
    assert seen[2.0][:2] == pytest.approx((261.5 + 1.25, -11.5), abs=1e-6)
    x, y, h = seen[6.0]
    assert (x, y) == pytest.approx((261.5 + 1.25, -11.5 + 20.0), abs=1e-6) and h == pytest.approx(
        math.pi / 2
    )
