"""RoadGeometry read from SUMO nets: lane sizes, borders, markings, junctions, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from lxml import etree
from shapely.geometry import Point

from hiyari.errors import HiyariError
from hiyari.net.road.geometry import LaneKind, RoadGeometry, parse_shape
from hiyari.net.sumo.build import (
    CityGridParams,
    ExpresswayParams,
    build_city_grid,
    build_expressway,
)
from hiyari.net.sumo.plain_xml import build_net


@pytest.fixture(scope="module")
def nets(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("geom")
    return {
        "city": build_city_grid(tmp / "city.net.xml", CityGridParams(blocks_x=2, blocks_y=2)),
        "expressway": build_expressway(tmp / "ex.net.xml", ExpresswayParams()),
    }


@pytest.mark.parametrize("name", ["city", "expressway"])
def test_lane_polygons_have_sumo_widths_and_lengths(nets, name):
    net = nets[name]
    g = RoadGeometry.from_net(net)
    sumo = {
        ln.get("id"): (float(ln.get("width", 3.2)), float(ln.get("length")))
        for ln in etree.parse(str(net)).getroot().iter("lane")
    }
    # SUMO gives every lane of an edge the edge's length, so on curves the inner and outer
    # lanes' shapes are shorter / longer than it: compare on straight edges only.
    straight = {"east_in", "east_nose", "east_merge"} if name == "expressway" else None
    lanes = [
        ln
        for ln in g.lanes_of(LaneKind.DRIVING, LaneKind.SIDEWALK)
        if straight is None or ln.edge in straight
    ]
    assert len(lanes) > 6
    for lane in lanes:
        width, length = sumo[lane.id]
        assert lane.width == width
        centre_length = np.sum(np.linalg.norm(np.diff(lane.centre, axis=0), axis=1))
        assert centre_length == pytest.approx(length, rel=1e-3, abs=0.02)
        plan_length = np.sum(np.hypot(*np.diff(lane.centre[:, :2], axis=0).T))
        assert lane.polygon.is_valid
        assert lane.polygon.area / plan_length == pytest.approx(width, rel=0.01)
        # every border point lies half a width from the centre line
        gap = np.hypot(*(lane.left[:, :2] - lane.right[:, :2]).T)
        assert np.all(gap >= width - 0.01)


def test_neighbouring_lanes_share_borders_and_heights(nets):
    g = RoadGeometry.from_net(nets["expressway"])
    for edge in ("east_merge", "east_mid", "west"):
        lanes = [g.lanes[f"{edge}_{i}"] for i in range(len(g.edges[edge].lanes))]
        for right, left in zip(lanes[:-1], lanes[1:], strict=True):
            np.testing.assert_array_equal(right.left, left.right)
            # border height lies halfway between the two lane centres (equal widths)
            np.testing.assert_allclose(
                right.left[:, 2], 0.5 * (right.heights + left.heights), atol=1e-9
            )


def test_pedestrian_parts_and_junctions(nets):
    g = RoadGeometry.from_net(nets["city"])
    assert len(g.sidewalks) == sum(1 for e in g.edges.values() if e.function == "")
    assert all(s.width == 3.0 for s in g.sidewalks)
    assert len(g.crossings) == 36 and all(c.width == 4.0 for c in g.crossings)
    assert all(w.polygon.area > 1.0 for w in g.walking_areas if w.edge.startswith(":g1_1"))
    centre = g.junctions["g1_1"].polygon
    assert centre.area > 150.0 and centre.contains(Point(200.0, 200.0))
    # every crossing lies inside its junction's area
    for c in g.crossings:
        junction = g.junctions[c.edge[1:].rsplit("_", 1)[0]]
        assert junction.polygon.buffer(0.05).contains(c.polygon)


def test_road_boundaries(nets):
    city = RoadGeometry.from_net(nets["city"])
    normal = sum(1 for e in city.edges.values() if e.function == "")
    assert len(city.boundaries) == 2 * normal
    for b in city.boundaries:
        lane = city.lanes[b.lane]
        assert b.kerb == (b.side == "right") and b.outermost == (b.side == "left")
        np.testing.assert_array_equal(b.line, lane.right if b.side == "right" else lane.left)
    ex = RoadGeometry.from_net(nets["expressway"])
    merge = {b.side: b for b in ex.boundaries if b.edge == "east_merge"}
    assert merge["right"].lane == "east_merge_0" and merge["left"].lane == "east_merge_2"
    assert all(b.outermost and not b.kerb for b in ex.boundaries)


def test_markings_follow_lane_change_permissions(tmp_path):
    nodes = [{"id": "a", "x": 0, "y": 0}, {"id": "b", "x": 200, "y": 0}]
    edges = [
        {
            "id": "road",
            "from": "a",
            "to": "b",
            "numLanes": 3,
            "speed": 27.0,
            # lane 0 <-> 1: no change for cars (solid); lane 1 <-> 2: free (dashed)
            "lanes": [
                {"index": 0, "changeLeft": "emergency"},
                {"index": 1, "changeRight": "emergency"},
            ],
        }
    ]
    net = build_net(tmp_path / "m.net.xml", nodes, edges, [], "test net")
    g = RoadGeometry.from_net(net)
    styles = {(m.lane, m.inset): m.style for m in g.markings}
    assert styles == {
        ("road_0", +1): "solid",  # right edge line
        ("road_2", -1): "solid",  # left edge line
        ("road_0", 0): "solid",
        ("road_1", 0): "dashed",
    }
    between = next(m for m in g.markings if m.lane == "road_1" and m.inset == 0)
    np.testing.assert_allclose(between.line, g.lanes["road_2"].right)


def test_shape_parsing_with_omitted_zero_heights():
    shape = parse_shape("0.00,1.00,2.50 3.00,4.00 5.00,6.00,-1.00")
    np.testing.assert_array_equal(shape, [[0, 1, 2.5], [3, 4, 0], [5, 6, -1]])


def test_no_drivable_lanes_is_one_error_line(tmp_path):
    nodes = [{"id": "a", "x": 0, "y": 0}, {"id": "b", "x": 50, "y": 0}]
    edges = [{"id": "path", "from": "a", "to": "b", "allow": "pedestrian", "width": 2.0}]
    net = build_net(tmp_path / "walk.net.xml", nodes, edges, [], "footpath")
    with pytest.raises(HiyariError, match="no drivable lanes") as err:
        RoadGeometry.from_net(net)
    assert "\n" not in str(err.value)


def test_not_a_net_is_one_error_line(tmp_path):
    bad = tmp_path / "x.net.xml"
    bad.write_text("<net><edge id='e'><lane id='e_0' shape='0,0 1")
    with pytest.raises(HiyariError, match="not well-formed XML"):
        RoadGeometry.from_net(bad)
    other = tmp_path / "y.net.xml"
    other.write_text("<routes/>")
    with pytest.raises(HiyariError, match="not a SUMO network"):
        RoadGeometry.from_net(other)
