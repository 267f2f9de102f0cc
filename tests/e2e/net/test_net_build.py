"""Generated networks: SUMO loads them and drives traffic; their geometry is what was asked for."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from hiyari.errors import HiyariError
from hiyari.net.road.geometry import LaneKind, RoadGeometry
from hiyari.net.sumo.alignment import Alignment, Element
from hiyari.net.sumo.build import (
    CityGridParams,
    ExpresswayParams,
    IntersectionParams,
    R157RoadParams,
    build_city_grid,
    build_expressway,
    build_intersection,
    build_r157_road,
)
from hiyari.traffic import DemandConfig, SimConfig, Simulation, write_demand

#: A short expressway with every feature (curve, both ramps) so SUMO runs stay quick.
SHORT_EXPRESSWAY = ExpresswayParams(
    length=1500.0,
    merge_station=400.0,
    accel_length=200.0,
    diverge_station=1200.0,
    decel_length=150.0,
    ramp_length=200.0,
    curve_start=600.0,
    curve_length=100.0,
    transition_length=50.0,
    curve_radius=300.0,
    gradient=0.02,
)


def _edges_seen(net: Path, tmp: Path, vph: float, pph: float, seconds: float) -> dict[str, set]:
    """Run SUMO on ``net`` with generated demand; vehicle / person id -> edges it was on."""
    demand = write_demand(
        net,
        tmp / f"{net.stem}.rou.xml",
        DemandConfig(vehicles_per_hour=vph, persons_per_hour=pph, end=seconds, seed=5),
    )
    seen: dict[str, set] = {}
    config = SimConfig(net=net, routes=[demand], step_length=0.5, end_time=seconds)
    with Simulation(config) as sim:
        for state in sim.run():
            for actor, edge in zip(state.ids, state.edge, strict=True):
                seen.setdefault(str(actor), set()).add(str(edge))
    return seen


def test_expressway_merge_and_branch_carry_traffic(tmp_path):
    net = build_expressway(tmp_path / "ex.net.xml", SHORT_EXPRESSWAY)
    seen = _edges_seen(net, tmp_path, vph=2400, pph=0, seconds=120)
    merged = [v for v, e in seen.items() if "onramp" in e and "east_mid" in e]
    branched = [v for v, e in seen.items() if "east_in" in e and "offramp" in e]
    assert len(seen) > 40
    assert len(merged) >= 5 and len(branched) >= 5


def test_expressway_lanes_ramps_and_roadside(tmp_path):
    p = SHORT_EXPRESSWAY
    g = RoadGeometry.from_net(build_expressway(tmp_path / "ex.net.xml", p))
    lanes_of = {e.id: len(e.lanes) for e in g.edges.values() if e.function == ""}
    assert lanes_of == {
        "east_in": 2,
        "east_nose": 2,
        "east_merge": 3,
        "east_mid": 2,
        "east_diverge": 3,
        "east_gore": 2,
        "east_out": 2,
        "west": 2,
        "onramp": 1,
        "offramp": 1,
    }
    for lane in g.driving_lanes:
        assert lane.width == pytest.approx(p.lane_width)
    assert g.edges["east_in"].barriers == {"left", "right"}
    assert g.edges["east_nose"].barriers == {"left"}
    assert g.edges["east_in"].shoulder_right == p.shoulder_right
    assert g.edges["east_nose"].shoulder_right == 0.0


def test_expressway_curve_radius_superelevation_and_gradient(tmp_path):
    p = SHORT_EXPRESSWAY
    g = RoadGeometry.from_net(build_expressway(tmp_path / "ex.net.xml", p))
    # The arc (stations 650..750) lies in east_mid; its centre from the alignment.
    a = Alignment.from_elements(
        [
            Element(p.curve_start, 0, 0),
            Element(p.transition_length, 0, 1 / p.curve_radius),
            Element(p.curve_length, 1 / p.curve_radius, 1 / p.curve_radius),
        ]
    )
    s_mid = p.curve_start + p.transition_length + p.curve_length / 2
    xy, h = a.frame(np.array([s_mid]))
    centre = xy[0] + p.curve_radius * np.array([-math.sin(h[0]), math.cos(h[0])])
    for i in range(p.lanes):
        lane = g.lanes[f"east_mid_{i}"]
        offset = p.median_width / 2 + (p.lanes - i - 0.5) * p.lane_width
        r = np.hypot(*(lane.centre[:, :2] - centre).T)
        on_arc = np.abs(r - (p.curve_radius + offset)) < 0.05
        # the arc is 100 m long: at 2 m spacing that is about 50 lane points
        assert on_arc.sum() >= 40
    # Superelevation: on the arc the outer (right) lane is higher by e x lane width.
    z0, z1 = (g.lanes[f"east_mid_{i}"].centre for i in (0, 1))
    r0 = np.hypot(*(z0[:, :2] - centre).T)
    arc = np.abs(r0 - (p.curve_radius + p.median_width / 2 + 1.5 * p.lane_width)) < 0.05
    assert np.median(z0[arc, 2] - z1[arc, 2]) == pytest.approx(
        p.superelevation * p.lane_width, abs=0.01
    )
    # Straight before the curve: normal cross slope falls to the outside.
    straight = g.lanes["east_in_0"].centre[0, 2] - g.lanes["east_in_1"].centre[0, 2]
    assert straight == pytest.approx(-p.cross_slope * p.lane_width, abs=0.01)
    # Gradient: the westbound lane rises 2 % over the main line's length.
    west = g.lanes["west_0"].centre
    assert west[0, 2] - west[-1, 2] == pytest.approx(p.gradient * p.length, abs=0.05)


def test_city_grid_with_pedestrians(tmp_path):
    params = CityGridParams(blocks_x=2, blocks_y=2, block_length=120.0, attach_length=60.0)
    net = build_city_grid(tmp_path / "city.net.xml", params)
    g = RoadGeometry.from_net(net)
    assert {"g0_0", "g2_2", "g1_1"} <= set(g.junctions)
    assert len(g.crossings) == 9 * 4  # four crossings at each of the 3 x 3 intersections
    tls = etree.parse(str(net)).getroot().findall("tlLogic")
    assert len(tls) == 9
    seen = _edges_seen(net, tmp_path, vph=1800, pph=1800, seconds=90)
    persons = [k for k in seen if k.startswith("ped")]
    vehicles = [k for k in seen if k.startswith("veh")]
    assert len(persons) > 10 and len(vehicles) > 10
    crossed = [k for k in persons if any("_c" in e for e in seen[k])]
    assert crossed


def test_intersection_with_traffic_light(tmp_path):
    net = build_intersection(tmp_path / "x.net.xml", IntersectionParams(traffic_light=True))
    g = RoadGeometry.from_net(net)
    assert len(g.sidewalks) == 8 and len(g.crossings) == 4 and len(g.walking_areas) >= 4
    assert etree.parse(str(net)).getroot().find("tlLogic") is not None
    seen = _edges_seen(net, tmp_path, vph=900, pph=900, seconds=90)
    assert sum(k.startswith("veh") for k in seen) > 10


def test_r157_road_has_exactly_two_3_5_m_lanes(tmp_path):
    p = R157RoadParams()
    net = build_r157_road(tmp_path / "r157.net.xml", p)
    g = RoadGeometry.from_net(net)
    normal = [ln for ln in g.lanes.values() if not ln.internal]
    assert sorted(ln.id for ln in normal) == ["road_0", "road_1"]
    assert all(ln.kind == LaneKind.DRIVING for ln in normal)
    right, left = g.lanes["road_0"], g.lanes["road_1"]
    assert right.width == left.width == 3.5
    assert right.length == left.length == pytest.approx(3000.0)
    np.testing.assert_allclose(right.centre[:, 1], -1.75)
    np.testing.assert_allclose(left.centre[:, 1], 1.75)
    np.testing.assert_allclose(right.centre[[0, -1], 0], [0.0, 3000.0])
    # One edge has no origin-destination pair for generated demand: route cars along it.
    routes = etree.Element("routes")
    etree.SubElement(routes, "route", id="r", edges="road")
    for k in range(20):
        etree.SubElement(
            routes,
            "vehicle",
            id=f"v{k}",
            route="r",
            depart=str(2 * k),
            departLane=str(k % 2),
            departSpeed="max",
        )
    rou = tmp_path / "r157.rou.xml"
    etree.ElementTree(routes).write(str(rou))
    lanes_used, max_x = set(), 0.0
    config = SimConfig(net=net, routes=[rou], step_length=0.5, end_time=60)
    with Simulation(config) as sim:
        for state in sim.run():
            lanes_used.update(str(v) for v in state.lane)
            if len(state):
                max_x = max(max_x, float(state.xyz[:, 0].max()))
    assert lanes_used == {"road_0", "road_1"}
    assert max_x > 1000.0  # 60 s at up to 36 m/s


@pytest.mark.parametrize(
    ("builder", "params", "words"),
    [
        (build_expressway, ExpresswayParams(curve_radius=20.0), "curve radius"),
        (build_expressway, ExpresswayParams(merge_station=2600.0), "stations must increase"),
        (build_expressway, ExpresswayParams(lanes=0), "lane"),
        (build_city_grid, CityGridParams(blocks_x=0), "blocks_x"),
        (build_r157_road, R157RoadParams(lane_width=1.0), "lane width"),
        (build_intersection, IntersectionParams(lane_width=1.0), "lane width"),
    ],
)
def test_impossible_parameters_one_line_no_file(tmp_path, builder, params, words):
    out = tmp_path / "bad.net.xml"
    with pytest.raises(HiyariError) as err:
        builder(out, params)
    assert words in str(err.value) and "\n" not in str(err.value)
    assert list(tmp_path.iterdir()) == []
