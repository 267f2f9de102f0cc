"""OpenStreetMap import: small OSM files written here (tests/support/osm_authoring.py) and the race
track shipped in the eclipse-sumo wheel, converted by the real netconvert / polyconvert."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
import osmium
import pytest
import shapely
from lxml import etree
from osm_authoring import OsmDoc, town

from hiyari.bridge.cli.main import main
from hiyari.errors import HiyariError
from hiyari.net.road.buildings import DEFAULT_HEIGHT, building_height, parse_height, poly_path
from hiyari.net.road.geometry import LaneKind, RoadGeometry
from hiyari.net.road.network import RoadNetwork
from hiyari.net.sumo.osm import OsmImportOptions, import_osm
from hiyari.sumo_tools import check_net_loads, sumo_home


@pytest.fixture(scope="module")
def town_net(tmp_path_factory):
    """The town layout imported once: (doc, net path)."""
    folder = tmp_path_factory.mktemp("town")
    doc = town()
    osm = doc.write(folder / "town.osm")
    return doc, import_osm(osm, folder / "town.net.xml")


def _edges_of_way(g: RoadGeometry, way: int) -> list:
    """The normal edges netconvert made from OSM way ``way`` (both directions, all pieces)."""
    ids = {str(way), f"-{way}"}
    return [e for e in g.edges.values() if e.function == "" and e.id.split("#")[0] in ids]


def _node_xy(net: Path, node: str) -> np.ndarray:
    """Where netconvert put the junction of OSM node ``node``, network metres."""
    return np.array(RoadNetwork(net).sumo.getNode(node).getCoord()[:2])


def _kinds(g: RoadGeometry, edge) -> list[LaneKind]:
    return [g.lanes[i].kind for i in edge.lanes]


def test_town_lanes_speeds_sidewalks_from_the_tags(town_net):
    doc, net = town_net
    g = RoadGeometry.from_net(net)
    main_edges = _edges_of_way(g, doc.ids["main"])
    assert main_edges
    for e in main_edges:  # lanes=4 on a two-way street: two each way, a 3 m primary sidewalk
        kinds = _kinds(g, e)
        assert kinds.count(LaneKind.DRIVING) == 2 and kinds.count(LaneKind.SIDEWALK) == 1
        walk = next(g.lanes[i] for i in e.lanes if g.lanes[i].kind == LaneKind.SIDEWALK)
        assert walk.width == pytest.approx(3.0)
        assert max(g.lanes[i].speed for i in e.lanes) == pytest.approx(50 / 3.6, abs=0.01)
    for e in _edges_of_way(g, doc.ids["north"]):  # maxspeed=30
        assert g.lanes[e.lanes[-1]].speed == pytest.approx(30 / 3.6, abs=0.01)
    south = _edges_of_way(g, doc.ids["south"])
    assert south and all(LaneKind.SIDEWALK in _kinds(g, e) for e in south)  # guessed
    f_i = _edges_of_way(g, doc.ids["F-I"])
    assert f_i and all(LaneKind.SIDEWALK not in _kinds(g, e) for e in f_i)  # sidewalk=no


def test_town_signal_crossings_and_scale(town_net):
    doc, net = town_net
    g = RoadGeometry.from_net(net)
    e, d = str(doc.ids["E"]), str(doc.ids["D"])
    assert g.junctions[e].type == "traffic_light"  # the mapped signal
    crossing = str(doc.ids["crossing"])
    at_zebra = [ln for ln in g.crossings if ln.id.startswith(f":{crossing}_c")]
    assert len(at_zebra) == 2  # the mapped zebra: one crossing over each direction
    assert any(ln.id.startswith(f":{e}_c") for ln in g.crossings)  # guessed at the junction
    # junctions keep OSM's node ids; 100 m apart on the map, 100 m apart in the net
    a, b = _node_xy(net, d), _node_xy(net, e)
    assert math.dist(a, b) == pytest.approx(100.0, abs=0.5)
    check_net_loads(net)


def test_town_buildings_heights_and_footprints(town_net):
    doc, net = town_net
    network = RoadNetwork(net)
    assert network.polygons == (poly_path(net),)
    by_id = {b.id: b for b in network.buildings}
    tall, levels = by_id[str(doc.ids["tall"])], by_id[str(doc.ids["levels"])]
    assert (tall.height, tall.rule) == (12.0, "height")
    assert (levels.height, levels.rule) == (15.0, "levels")
    for b in (tall, levels):  # 40 m x 40 m as mapped (UTM scale within 0.2 %)
        assert shapely.Polygon(b.outline).area == pytest.approx(1600.0, rel=0.01)
    # the tall building's south-west corner is 20 m east and 20 m north of junction E
    e = _node_xy(net, str(doc.ids["E"]))
    corner = tall.outline[np.argmin(tall.outline.sum(axis=1))]
    assert corner - e == pytest.approx([20.0, 20.0], abs=1.0)


@pytest.mark.parametrize(
    ("tags", "expected"),
    [
        ({"height": "12"}, (12.0, "height")),
        ({"height": "12.5 m", "building:levels": "9"}, (12.5, "height")),
        ({"height": "12,5m"}, (12.5, "height")),
        ({"height": "40 ft"}, (40 * 0.3048, "height")),
        ({"height": "10'6\""}, (10.5 * 0.3048, "height")),
        ({"height": "tall", "building:levels": "4"}, (12.0, "levels")),
        ({"height": "-3", "building:levels": "2.5"}, (7.5, "levels")),
        ({"building:levels": "0"}, (DEFAULT_HEIGHT, "default")),
        ({}, (DEFAULT_HEIGHT, "default")),
    ],
)
def test_building_height_rules(tags, expected):
    height, rule = building_height(tags)
    assert rule == expected[1] and height == pytest.approx(expected[0])


def test_parse_height_refuses_what_is_not_a_height():
    assert [parse_height(t) for t in ("", "12 km", "1e3", "nan", "0")] == [None] * 5


def test_repairs_one_line_each_and_the_file_untouched(tmp_path):
    doc = town()
    a, b = doc.ids["G"], doc.ids["I"]
    root = doc.root
    bad_lat = doc.node(50.0, 50.0)
    root[-1].set("lat", "abc")
    deleted = doc.node(60.0, 60.0)
    root[-1].set("action", "delete")
    root.insert(1, root[0].__copy__())  # node A again, right after itself
    way = doc.way([a, b], highway="residential")
    etree.SubElement(root[-1], "nd", ref="x")
    osm = doc.write(tmp_path / "repairs.osm")
    before = hashlib.sha256(osm.read_bytes()).hexdigest()
    warnings: list[str] = []
    net = import_osm(osm, tmp_path / "r.net.xml", warn=warnings.append)
    assert net.is_file() and hashlib.sha256(osm.read_bytes()).hexdigest() == before
    assert len(warnings) == 4 and all(w.startswith(f"{osm}:") for w in warnings)
    text = "\n".join(warnings)
    assert f"<node id=\"{bad_lat}\">: lat 'abc' is not a number: dropped" in text
    assert f'<node id="{deleted}">: deleted in the editor (action=delete): dropped' in text
    first = doc.ids["A"]
    assert f'<node id="{first}">: repeats node id {first}: dropped, the first one kept' in text
    assert f'<way id="{way}"> <nd ref="x">: not a node id: dropped from the way' in text


def test_pbf_imports_as_its_xml(tmp_path, town_net):
    doc, xml_net = town_net
    osm = doc.write(tmp_path / "town.osm")
    pbf = tmp_path / "town.osm.pbf"
    with osmium.SimpleWriter(str(pbf)) as writer:
        for obj in osmium.FileProcessor(str(osm)):
            writer.add(obj)
    net = import_osm(pbf, tmp_path / "pbf.net.xml")
    a, b = RoadGeometry.from_net(xml_net), RoadGeometry.from_net(net)
    assert sorted(a.lanes) == sorted(b.lanes)
    for lane_id, lane in a.lanes.items():
        assert np.allclose(lane.centre, b.lanes[lane_id].centre)
    assert len(RoadNetwork(net).buildings) == 2


def test_bbox_cuts_the_west_blocks(tmp_path, town_net):
    doc, full = town_net
    osm = doc.write(tmp_path / "town.osm")
    # x from -110 m to -60 m: the west column's streets and every edge from it, whole
    (s, w), (n, e) = doc.latlon(-110.0, -110.0), doc.latlon(-60.0, 110.0)
    net = import_osm(osm, tmp_path / "west.net.xml", OsmImportOptions(bbox=(w, s, e, n)))
    g, whole = RoadGeometry.from_net(net), RoadGeometry.from_net(full)
    assert 0 < len(g.edges) < len(whole.edges)
    kept = {k for k in [*"ABCDEFGHI", "crossing"] if str(doc.ids[k]) in g.junctions}
    # B, H and the zebra end edges that reach into the box (G is a bend inside edge D-H)
    assert kept == {"A", "B", "D", "H", "crossing"}


def test_race_track_from_the_wheel(tmp_path):
    osm = sumo_home() / "tools" / "game" / "racing" / "spreewaldring.osm"
    net = import_osm(osm, tmp_path / "ring.net.xml")
    g = RoadGeometry.from_net(net)
    assert len(g.driving_lanes) > 10
    check_net_loads(net)


def _no_highway(path: Path) -> None:
    doc = OsmDoc()
    doc.building(0.0, 0.0, 10.0, 10.0)
    doc.write(path)


@pytest.mark.parametrize(
    ("make", "args", "words"),
    [
        (lambda p: p.write_text(town().write(p).read_text()[:1500]), [], "not well-formed OSM XML"),
        (lambda p: p.write_text('<osm version="0.6"/>'), [], "has no node"),
        (lambda p: p.write_text("<html><body/></html>"), [], "not an OpenStreetMap file"),
        (_no_highway, [], "no highway=* way"),
        (lambda p: town().write(p), ["--bbox", "10,40,10.1,40.1"], "lies outside the map"),
        (lambda p: town().write(p), ["--bbox", "13.41,52.5,13.40,52.6"], "west < east"),
        (lambda p: p.write_bytes(b"\x00\x01 not a pbf"), [], "cannot read the OSM PBF file"),
    ],
)
def test_bad_extracts_one_line_exit_1(tmp_path, capsys, make, args, words):
    src = tmp_path / ("bad.osm.pbf" if "PBF" in words else "bad.osm")
    make(src)
    out = tmp_path / "out" / "bad.net.xml"
    assert main(["net", "import", str(src), "-o", str(out), *args]) == 1
    err = capsys.readouterr().err
    assert err.startswith("hiyari: error: ") and words in err and err.count("\n") == 1
    assert str(src) in err or "--bbox" in err
    assert not out.parent.exists()


def test_cli_import_prints_the_network_and_buildings(tmp_path, capsys):
    osm = town().write(tmp_path / "town.osm")
    out = tmp_path / "town.net.xml"
    assert main(["net", "import", str(osm), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"network: {out}" in printed and "buildings: " in printed and "(2 buildings)" in printed
    assert main(["net", "import", str(osm), "-o", str(tmp_path / "bare.net.xml"),
                 "--no-buildings"]) == 0  # fmt: skip
    assert not (tmp_path / "bare.poly.xml").exists()


def test_import_refuses_what_is_missing(tmp_path):
    with pytest.raises(HiyariError, match="OpenStreetMap file not found"):
        import_osm(tmp_path / "nothing.osm", tmp_path / "x.net.xml")
