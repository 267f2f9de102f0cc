"""Direct junctions import with exactly the file's lane links, in both driving directions.

Edge "-<road>" carries a road's right lanes (driving along s), "<road>" its left lanes; lane
index 0 is the outermost lane. Each expected set below is read off the file by hand.
"""

from __future__ import annotations

from lxml import etree
from xodr_authoring import TOWN, junction, opendrive, road, write

from hiyari.net.sumo.opendrive import import_opendrive

D = ("driving", 3.5)


def _links(net) -> set[tuple[str, str]]:
    """The net's lane-to-lane links between ordinary edges."""
    root = etree.parse(str(net)).getroot()
    return {
        (f"{c.get('from')}_{c.get('fromLane')}", f"{c.get('to')}_{c.get('toLane')}")
        for c in root.iterfind("connection")
        if not c.get("from").startswith(":")
    }


def test_linked_road_that_is_also_incoming_keeps_its_reverse_link(tmp_path):
    """Road 1 (1+1 lanes, x 0..100) runs on into road 2 (2+1 lanes, x 100..200) in direct
    junction 7; road 2's outer left lane 2 leaves into road 3 (one left lane, y 3.5..7, ending
    at x = 100), a second connection whose incoming road is road 2 itself."""
    root = opendrive()
    road(root, 1, (0.0, 0.0, 0.0), 100.0, {1: D, -1: D}, links=[("successor", "junction", 7, None)])
    road(root, 2, (100.0, 0.0, 0.0), 100.0, {2: D, 1: D, -1: D},
         links=[("predecessor", "junction", 7, None)])  # fmt: skip
    road(root, 3, (40.0, 3.5, 0.0), 60.0, {1: D}, links=[("successor", "junction", 7, None)])
    junction(root, 7, [
        (1, None, "start", [(1, 1), (-1, -1)], {"linkedRoad": "2"}),
        (2, None, "end", [(2, 1)], {"linkedRoad": "3"}),
    ], type="direct")  # fmt: skip
    src = write(root, tmp_path / "linked_incoming.xodr")
    net = import_opendrive(src, tmp_path / "n.net.xml", warn=lambda m: None)
    assert _links(net) == {
        ("-1_0", "-2_0"),  # road 1 lane -1 -> road 2 lane -1, along s
        ("2_1", "1_0"),  # road 2 lane 1 -> road 1 lane 1, against s (the link netconvert lost)
        ("2_0", "3_0"),  # road 2 lane 2 -> road 3 lane 1
    }


def test_exit_gets_no_link_from_the_other_carriageway(tmp_path):
    """Road 1 (1 left, 2 right lanes) runs on into road 2 (1+1) and its outer right lane -2
    leaves into road 3 (one right lane) in direct junction 8; road 2's left lane may only go
    back into road 1, never across the median into the exit."""
    root = opendrive()
    road(root, 1, (0.0, 0.0, 0.0), 100.0, {1: D, -1: D, -2: D},
         links=[("successor", "junction", 8, None)])  # fmt: skip
    road(root, 2, (100.0, 0.0, 0.0), 100.0, {1: D, -1: D},
         links=[("predecessor", "junction", 8, None)])  # fmt: skip
    road(root, 3, (100.0, -3.5, 0.0), 60.0, {-1: D}, links=[("predecessor", "junction", 8, None)])
    junction(root, 8, [
        (1, None, "start", [(1, 1), (-1, -1)], {"linkedRoad": "2"}),
        (1, None, "start", [(-2, -1)], {"linkedRoad": "3"}),
    ], type="direct")  # fmt: skip
    src = write(root, tmp_path / "exit.xodr")
    net = import_opendrive(src, tmp_path / "n.net.xml", warn=lambda m: None)
    assert _links(net) == {
        ("-1_1", "-2_0"),  # road 1 lane -1 (inner, index 1) -> road 2 lane -1
        ("-1_0", "-3_0"),  # road 1 lane -2 (outer) -> exit road 3 lane -1
        ("2_0", "1_0"),  # road 2 lane 1 -> road 1 lane 1; no ("2_0", "-3_0") across the median
    }


def test_sidewalks_of_a_direct_junction_are_left_to_walking_areas(tmp_path):
    """Road 1 runs on into road 2 (median, driving lane, border, sidewalk per side) in direct
    junction 9, every lane linked to its namesake: the driving links are the file's, and the
    sidewalks (lane index 0) keep netconvert's walking areas (no link of theirs is patched)."""
    root = opendrive()
    road(root, 1, (0.0, 0.0, 0.0), 100.0, TOWN, links=[("successor", "junction", 9, None)])
    road(root, 2, (100.0, 0.0, 0.0), 100.0, TOWN, links=[("predecessor", "junction", 9, None)])
    junction(root, 9, [(1, None, "start", [(k, k) for k in TOWN], {"linkedRoad": "2"})],
             type="direct")  # fmt: skip
    net = import_opendrive(write(root, tmp_path / "town.xodr"), tmp_path / "n.net.xml",
                           warn=lambda m: None)  # fmt: skip
    links = _links(net)
    assert {link for link in links if link[0].endswith("_1")} == {("-1_1", "-2_1"), ("2_1", "1_1")}
    assert {("2_0", ":9_w0_0"), ("-1_0", ":9_w1_0")} <= links  # sidewalks onto walking areas
