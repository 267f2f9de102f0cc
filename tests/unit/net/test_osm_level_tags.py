"""Bridge and tunnel heights from OSM tags (no SUMO): the level of a way, the level of the
nodes where levels meet, the slope limit, and the ele tags the repaired copy carries."""

from __future__ import annotations

import pytest
from lxml import etree

from hiyari.net.sumo.osm.levels import (
    LEVEL_HEIGHT,
    M_PER_DEG,
    MAX_GRADE,
    node_heights,
    node_levels,
    way_level,
    write_levels,
)


def test_way_level_from_layer_bridge_and_tunnel():
    assert way_level({"highway": "primary"}) == 0
    assert way_level({"bridge": "yes"}) == 1
    assert way_level({"bridge": "viaduct", "layer": "2"}) == 2
    assert way_level({"tunnel": "yes"}) == -1
    assert way_level({"tunnel": "yes", "layer": "-3"}) == -3
    assert way_level({"tunnel": "building_passage"}) == 0  # through a building, on the ground
    assert way_level({"bridge": "no", "tunnel": "no"}) == 0
    assert way_level({"layer": "-2;-1"}) == -2  # the first of a list
    assert way_level({"bridge": "yes", "layer": "x"}) == 1  # no integer: the bridge's 1


def _osm(ways: list[tuple[list[int], dict[str, str]]], step: float = 100.0) -> etree._Element:
    """Nodes 1..9 on the equator, node n at n * ``step`` m east."""
    root = etree.Element("osm")
    for n in range(1, 10):
        node = etree.SubElement(root, "node", id=str(n), lat="0", lon=repr(n * step / M_PER_DEG))
        etree.SubElement(node, "tag", k="ele", v="31.5")  # an altitude: dropped
    for k, (refs, tags) in enumerate(ways):
        way = etree.SubElement(root, "way", id=str(100 + k))
        for r in refs:
            etree.SubElement(way, "nd", ref=str(r))
        for key, v in {"highway": "secondary", **tags}.items():
            etree.SubElement(way, "tag", k=key, v=v)
    return root


def test_a_bridge_lifts_its_ends_and_the_approach_roads_ramp():
    # 1 -> 2 approach, 2 -> 3 bridge (no node between its ends), 3 -> 4 approach
    root = _osm([([1, 2], {}), ([2, 3], {"bridge": "yes"}), ([3, 4], {})])
    assert node_levels(root) == {"2": 1, "3": 1}
    assert write_levels(root) == 2
    ele = {n.get("id"): [t.get("v") for t in n.iter("tag")] for n in root.iter("node")}
    up = [f"{LEVEL_HEIGHT:g}"]  # "6"
    assert ele == {"1": [], "2": up, "3": up, "4": [], "5": [], "6": [], "7": [], "8": [], "9": []}


def test_a_tunnel_under_a_street_it_joins_keeps_the_street_on_the_ground():
    # street 1 -> 2 -> 3; a footway tunnel starts at its node 2 and runs 2 -> 5 -> 6, then
    # a deeper service tunnel 6 -> 7 (layer -3 after -1: the deeper one wins at 6)
    root = _osm([([1, 2, 3], {}), ([2, 5, 6], {"highway": "footway", "tunnel": "yes"}),
                 ([6, 7], {"tunnel": "yes", "layer": "-3"})])  # fmt: skip
    assert node_levels(root) == {"5": -1, "6": -3, "7": -3}


def test_ways_that_are_no_roads_give_no_level():
    root = _osm([([1, 2], {"highway": "secondary"})])
    rail = etree.SubElement(root, "way", id="200")
    for r in (2, 3):
        etree.SubElement(rail, "nd", ref=str(r))
    etree.SubElement(rail, "tag", k="railway", v="rail")
    etree.SubElement(rail, "tag", k="bridge", v="yes")
    assert node_levels(root) == {}


def test_no_slope_is_steeper_than_the_grade_limit():
    # a footway tunnel 1 -> 2 -> 3 -> 4 (nodes 6 m apart) ends at node 4 inside a ground
    # street 5 -> 4 -> 6: node 3 is 6 m from the ground, so 1.5 m down, not a layer's 6 m
    root = _osm([([1, 2, 3, 4], {"highway": "footway", "tunnel": "yes"}), ([5, 4, 6], {})],
                step=6.0)  # fmt: skip
    assert node_levels(root) == {"1": -1, "2": -1, "3": -1}
    assert node_heights(root) == pytest.approx(
        {"3": -MAX_GRADE * 6.0, "2": -MAX_GRADE * 12.0, "1": -MAX_GRADE * 18.0}, abs=0.01
    )
