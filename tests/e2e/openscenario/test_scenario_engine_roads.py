"""OpenDRIVE road / lane / s positions on the ALKS curved roads: exact against the arc's
closed form, and on the right SUMO lane at the right place (SUMO's own map matching)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from openscenario_files import ROADS, net_for, scenario_xml, teleport_speed, write

from hiyari.errors import HiyariError
from hiyari.net.road.opendrive_lanes import OpenDriveMap, RoadLanes
from hiyari.traffic.simulation import SimConfig, Simulation

CURVES = ROADS / "alks_road_different_curvatures.xodr"
LEFT_250 = ROADS / "alks_road_left_radius_250m.xodr"
# lane -4 centre: t = -(2 + 0.75 + 3.5 + 1.75) m
T_LANE_4 = -8.0


@pytest.fixture(scope="module")
def work(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("roads")


def test_reference_line_is_continuous_over_line_spiral_arc() -> None:
    road = OpenDriveMap.from_file(CURVES).road("0")
    kinds = {g.kind for g in road.geometries}
    assert kinds == {"line", "spiral", "arc"}
    for g, nxt in zip(road.geometries[:-1], road.geometries[1:], strict=True):
        x, y, h = g.pose(np.array([g.length]))
        assert math.hypot(x[0] - nxt.x, y[0] - nxt.y) < 1e-6
        assert abs(math.remainder(h[0] - nxt.hdg, 2 * math.pi)) < 1e-9


def test_lane_positions_match_the_arc_closed_form() -> None:
    """Left arc R = 250 m from (0, 0) heading +x: centre (0, 250); a point at s, t lies at
    radius R - t, angle s / R."""
    odr = OpenDriveMap.from_file(LEFT_250)
    s = np.array([0.0, 10.0, 333.3, 1000.0, 1499.0])
    x, y, _, h = odr.lane_pose("0", -4, s, np.full(len(s), 0.4))
    r = 250.0 - (T_LANE_4 + 0.4)
    assert np.allclose(x, r * np.sin(s / 250.0), atol=1e-9)
    assert np.allclose(y, 250.0 - r * np.cos(s / 250.0), atol=1e-9)
    assert np.allclose(h, s / 250.0, atol=1e-12)
    back = odr.locate(x, y)
    assert [b.lane for b in back] == [-4] * len(s)
    assert np.allclose([b.s for b in back], s, atol=1e-6)
    assert np.allclose([b.offset for b in back], 0.4, atol=1e-6)


@pytest.mark.parametrize("xodr", [LEFT_250, CURVES], ids=["R250", "curvatures"])
def test_lane_positions_land_on_the_right_sumo_lane(work: Path, xodr: Path) -> None:
    """Every lane -3 / -4 / -5 / 3 position maps to the SUMO lane netconvert made from it, and
    SUMO's own conversions agree with the exact point within 0.1 m."""
    net = net_for(xodr, work)
    roads = RoadLanes.from_files(xodr, net)
    length = roads.odr.road("0").length
    with Simulation(SimConfig(net=net)) as sim:
        for lane in (-3, -4, -5, 3):
            for s in np.linspace(3.0, length - 3.0, 23):
                p = roads.place("0", lane, float(s), 0.0)
                assert roads.origin_of(p.sumo_lane) == ("0", lane, 0)
                sx, sy = sim.lane_point(p.sumo_edge, p.pos, p.lane_index)
                assert math.hypot(sx - p.x, sy - p.y) < 0.1
                edge, pos, index = sim.road_position(p.x, p.y)
                assert (edge, index) == (p.sumo_edge, p.lane_index)
                assert abs(pos - p.pos) < 0.1
                assert abs(p.lateral) < 0.1


def test_teleported_actor_is_where_the_lane_position_says(work: Path) -> None:
    """An entity teleported to road 0 / lane -4 / s = 700 on the curved road appears in the
    WorldState with its box centre 1.4 m ahead of that point along the lane (within 0.1 m)."""
    from hiyari.bridge.openscenario.engine import ScenarioEngine
    from hiyari.bridge.openscenario.xosc.reader import read_scenario

    xml = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -4, 5.0, 0.0) + teleport_speed("Car", -3, 700.0, 0.0, offset=0.3),
        road=CURVES,
    )
    sc = read_scenario(write(work / "tele.xosc", xml))
    net = net_for(CURVES, work)
    roads = RoadLanes.from_files(CURVES, net)
    x, y, _, h = roads.odr.lane_pose("0", -3, np.array([700.0]), np.array([0.3]))
    with Simulation(SimConfig(net=net, step_length=0.05)) as sim:
        ScenarioEngine(sc, roads, 0.05).start(sim)
        w = sim.step()
        k = w.index("Car")
        cx, cy = x[0] + 1.4 * math.cos(h[0]), y[0] + 1.4 * math.sin(h[0])
        assert math.hypot(w.xyz[k, 0] - cx, w.xyz[k, 1] - cy) < 0.1
        assert abs(math.remainder(w.heading[k] - h[0], 2 * math.pi)) < 1e-3
        assert roads.origin_of(str(w.lane[k])) == ("0", -3, 0)


def test_off_road_position_is_refused() -> None:
    odr = OpenDriveMap.from_file(LEFT_250)
    with pytest.raises(HiyariError, match="no lane 9"):
        odr.lane_pose("0", 9, np.array([5.0]), np.array([0.0]))
    with pytest.raises(HiyariError, match="no road with id '7'"):
        odr.road("7")
