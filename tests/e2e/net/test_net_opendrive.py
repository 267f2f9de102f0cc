"""OpenDRIVE import: the ALKS roads and hand-written maps convert, keep heights and radii, run.

Heights and radii are checked in the 3D scene mesh against the values written in the
OpenDRIVE files (elevation polynomial, arc curvature, lane widths).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from lxml import etree
from paths import SHARED

from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.road_mesh import MeshParams, build_scene_mesh
from hiyari.net.road.geometry import LaneKind, RoadGeometry
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.traffic import DemandConfig, SimConfig, Simulation, write_demand

ALKS = SHARED / "data" / "opendrive" / "alks"
ALKS_FILES = sorted(ALKS.glob("*.xodr"))
LANE_WIDTH = 3.5


def _road(root, rid, x, y, hdg, length, shape, sections, junction="-1", elevation=None, links=()):
    """Append a <road>: ``shape`` is ("line",) or ("arc", curvature); ``sections`` maps
    s -> (left lane ids, right lane ids); ``links`` are (tag, elementType, elementId, contact).
    """
    road = etree.SubElement(
        root, "road", id=str(rid), length=repr(length), junction=str(junction), name=f"r{rid}"
    )
    link = etree.SubElement(road, "link")
    for tag, kind, element, contact in links:
        attrs = {"elementType": kind, "elementId": str(element)}
        if contact:
            attrs["contactPoint"] = contact
        etree.SubElement(link, tag, attrs)
    plan = etree.SubElement(road, "planView")
    geom = etree.SubElement(
        plan, "geometry", s="0", x=repr(x), y=repr(y), hdg=repr(hdg), length=repr(length)
    )
    if shape[0] == "line":
        etree.SubElement(geom, "line")
    else:
        etree.SubElement(geom, "arc", curvature=repr(shape[1]))
    if elevation is not None:
        prof = etree.SubElement(road, "elevationProfile")
        a, b, c, d = elevation
        etree.SubElement(prof, "elevation", s="0", a=repr(a), b=repr(b), c=repr(c), d=repr(d))
    lanes = etree.SubElement(road, "lanes")
    for s, (left, right) in sections.items():
        sec = etree.SubElement(lanes, "laneSection", s=repr(s))
        for side, ids in (("left", left), ("right", right)):
            if not ids:
                continue
            el = etree.SubElement(sec, side)
            for lid in ids:
                lane = etree.SubElement(el, "lane", id=str(lid), type="driving", level="false")
                lk = etree.SubElement(lane, "link")
                if s > 0:
                    etree.SubElement(lk, "predecessor", id=str(lid))
                etree.SubElement(
                    lane, "width", sOffset="0", a=repr(LANE_WIDTH), b="0", c="0", d="0"
                )
                etree.SubElement(
                    lane, "roadMark", sOffset="0", type="broken", weight="standard", width="0.15"
                )
        centre = etree.SubElement(sec, "center")
        etree.SubElement(centre, "lane", id="0", type="driving", level="false")
    return road


def _opendrive() -> etree._Element:
    root = etree.Element("OpenDRIVE")
    etree.SubElement(root, "header", revMajor="1", revMinor="6", name="hiyari test")
    return root


def _write(root, path: Path) -> Path:
    etree.ElementTree(root).write(str(path), xml_declaration=True, encoding="UTF-8")
    return path


ELEVATION = (5.0, 0.04, 2.0e-4, -4.0e-7)  # a + b s + c s^2 + d s^3, metres
RADIUS = 150.0


@pytest.fixture(scope="module")
def shaped_map(tmp_path_factory) -> tuple[Path, RoadGeometry]:
    """Road 1: straight along +x, 200 m, elevated; road 2: left arc R = 150 m, 300 m, grade."""
    root = _opendrive()
    _road(root, 1, 0.0, 0.0, 0.0, 200.0, ("line",), {0.0: ([1], [-1])}, elevation=ELEVATION)
    _road(
        root, 2, 0.0, 500.0, 0.0, 300.0, ("arc", 1.0 / RADIUS), {0.0: ([1], [-1])},
        elevation=(1.0, -0.03, 0.0, 0.0),
    )  # fmt: skip
    tmp = tmp_path_factory.mktemp("xodr")
    net = import_opendrive(_write(root, tmp / "shaped.xodr"), tmp / "shaped.net.xml")
    return net, RoadGeometry.from_net(net)


def _road_id(edge: str) -> str:
    """OpenDRIVE road id of a netconvert edge id ("-12#1": road 12, lane section 1)."""
    return edge.lstrip("-").split("#")[0]


def _road_vertices(g: RoadGeometry, road: str) -> np.ndarray:
    """Vertices of the lane-surface and paint triangles of one OpenDRIVE road's lanes."""
    lanes = [ln for ln in g.lanes.values() if _road_id(ln.edge) == road]
    sub = RoadGeometry(g.path, g.offset, {ln.id: ln for ln in lanes}, {}, {}, [], [])
    mesh = build_scene_mesh(sub, params=MeshParams(ground=False))
    used = mesh.faces[np.isin(mesh.material, [Material.ASPHALT, Material.LANE_PAINT])]
    return mesh.vertices[np.unique(used)] - np.array([*g.offset, 0.0])


def test_elevation_profile_is_kept_in_the_mesh(shaped_map):
    _, g = shaped_map
    v = _road_vertices(g, "1")
    s = v[:, 0]  # straight road along +x from the origin: s = x
    a, b, c, d = ELEVATION
    expected = a + b * s + c * s**2 + d * s**3
    assert len(v) > 100 and s.min() == pytest.approx(0.0) and s.max() == pytest.approx(200.0)
    np.testing.assert_allclose(v[:, 2], expected, atol=0.02)
    # lane borders at the OpenDRIVE lane widths: y in {-3.5, 0, 3.5}
    lanes = [ln for ln in g.driving_lanes if _road_id(ln.edge) == "1"]
    for ln in lanes:
        borders = np.concatenate([ln.left[:, 1], ln.right[:, 1]]) - g.offset[1]
        assert np.all(np.min(np.abs(borders[:, None] - [-3.5, 0.0, 3.5]), axis=1) < 0.01)


def test_arc_radius_and_grade_are_kept_in_the_mesh(shaped_map):
    _, g = shaped_map
    v = _road_vertices(g, "2")
    centre = np.array([0.0, 500.0 + RADIUS])  # left arc from (0, 500) heading +x
    r = np.hypot(*(v[:, :2] - centre).T)
    angle = np.arctan2(v[:, 0] - centre[0], centre[1] - v[:, 1])  # swept angle from the start
    s = angle * RADIUS
    inside = (s > 0.5) & (s < 299.5)
    assert inside.sum() > 200
    ring = np.min(np.abs(r[inside, None] - (RADIUS + np.array([-3.5, 0.0, 3.5]))), axis=1)
    assert ring.max() < 0.02
    np.testing.assert_allclose(v[inside, 2], 1.0 - 0.03 * s[inside], atol=0.02)


def _junction_map(path: Path) -> Path:
    """Road 1 (two lane sections: the second adds a right lane) into junction 100, which
    leads straight on to road 2 and, through a right-turn arc of 10 m radius, to road 3."""
    root = _opendrive()
    _road(
        root, 1, 0.0, 0.0, 0.0, 100.0, ("line",), {0.0: ([1], [-1]), 50.0: ([1], [-1, -2])},
        links=[("successor", "junction", 100, None)],
    )  # fmt: skip
    _road(
        root, 2, 120.0, 0.0, 0.0, 100.0, ("line",), {0.0: ([1], [-1])},
        links=[("predecessor", "junction", 100, None)],
    )  # fmt: skip
    _road(
        root, 3, 110.0, -10.0, -math.pi / 2, 100.0, ("line",), {0.0: ([], [-1])},
        links=[("predecessor", "junction", 100, None)],
    )  # fmt: skip
    straight = _road(
        root, 101, 100.0, 0.0, 0.0, 20.0, ("line",), {0.0: ([1], [-1])}, junction=100,
        links=[("predecessor", "road", 1, "end"), ("successor", "road", 2, "start")],
    )  # fmt: skip
    turn = _road(
        root, 102, 100.0, -3.5, 0.0, math.pi / 2 * 10.0, ("arc", -0.1), {0.0: ([], [-1])},
        junction=100,
        links=[("predecessor", "road", 1, "end"), ("successor", "road", 3, "start")],
    )  # fmt: skip
    for road, pairs in ((straight, {1: 1, -1: -1}), (turn, {-1: -1})):
        for lane in road.iter("lane"):
            lid = int(lane.get("id"))
            if lid in pairs:
                lk = lane.find("link")
                for old in list(lk):
                    lk.remove(old)
                etree.SubElement(lk, "predecessor", id=str(lid))
                etree.SubElement(lk, "successor", id=str(pairs[lid]))
    junction = etree.SubElement(root, "junction", id="100", name="j")
    for cid, (incoming, connecting, contact, links) in enumerate(
        [(1, 101, "start", [(-1, -1)]), (1, 102, "start", [(-2, -1)]), (2, 101, "end", [(1, 1)])]
    ):
        con = etree.SubElement(
            junction,
            "connection",
            id=str(cid),
            incomingRoad=str(incoming),
            connectingRoad=str(connecting),
            contactPoint=contact,
        )
        for a, b in links:
            etree.SubElement(con, "laneLink", attrib={"from": str(a), "to": str(b)})
    return _write(root, path)


def _drive(net: Path, tmp: Path, seconds: float = 60.0) -> dict[str, set]:
    demand = write_demand(
        net,
        tmp / f"{net.stem}.rou.xml",
        DemandConfig(vehicles_per_hour=1800, persons_per_hour=0, end=seconds, seed=2),
    )
    seen: dict[str, set] = {}
    with Simulation(SimConfig(net=net, routes=[demand], step_length=0.5, end_time=seconds)) as sim:
        for state in sim.run():
            for vid, edge in zip(state.ids, state.edge, strict=True):
                seen.setdefault(str(vid), set()).add(str(edge))
    return seen


def test_map_with_junction_and_lane_sections_runs_traffic(tmp_path):
    net = import_opendrive(_junction_map(tmp_path / "junction.xodr"), tmp_path / "j.net.xml")
    g = RoadGeometry.from_net(net)
    sections = sorted(e for e in g.edges if e.startswith("-1#"))
    assert [len(g.edges[e].lanes) for e in sections] == [1, 2]
    assert any(ln.internal and ln.kind == LaneKind.DRIVING for ln in g.lanes.values())
    assert g.junctions and max(j.polygon.area for j in g.junctions.values()) > 20.0
    seen = _drive(net, tmp_path)
    assert any("-3" in edges for edges in seen.values())  # the right turn
    assert any("-2" in edges for edges in seen.values())  # straight on
    assert any("2" in edges for edges in seen.values())  # the other direction


@pytest.mark.parametrize("xodr", ALKS_FILES, ids=[f.stem for f in ALKS_FILES])
def test_alks_roads_convert_load_and_run(tmp_path, xodr):
    net = import_opendrive(xodr, tmp_path / f"{xodr.stem}.net.xml")
    g = RoadGeometry.from_net(net)
    driving = [ln for ln in g.driving_lanes if ln.type == "driving"]
    assert len(driving) == 6 and all(ln.width == 3.5 for ln in driving)
    # Each carriageway is one edge without a way round: route cars along each edge.
    routes = etree.Element("routes")
    edges = sorted({ln.edge for ln in driving})
    for k in range(30):
        etree.SubElement(
            routes,
            "trip",
            id=f"v{k}",
            depart=str(k),
            departLane="best",
            departSpeed="max",
            attrib={"from": edges[k % 2], "to": edges[k % 2]},
        )
    rou = _write(routes, tmp_path / "alks.rou.xml")
    travelled: dict[str, float] = {}
    with Simulation(SimConfig(net=net, routes=[rou], step_length=0.5, end_time=60)) as sim:
        start: dict[str, np.ndarray] = {}
        for state in sim.run():
            for k, vid in enumerate(state.ids):
                start.setdefault(vid, state.xyz[k])
                travelled[vid] = float(np.linalg.norm(state.xyz[k] - start[vid]))
            lanes = {str(ln) for ln in state.lane}
            assert lanes <= {ln.id for ln in g.driving_lanes} | {""}
    assert len(travelled) == 30 and min(travelled.values()) > 50.0


def test_alks_curve_radius_in_the_mesh(tmp_path):
    net = import_opendrive(ALKS / "alks_road_left_radius_250m.xodr", tmp_path / "r250.net.xml")
    g = RoadGeometry.from_net(net)
    v = _road_vertices(g, "0")
    r = np.hypot(*(v[:, :2] - [0.0, 250.0]).T)  # curvature 0.004 from (0, 0), heading +x
    # lane borders: 2 m + 0.75 m border lanes, then 3.5 m lanes and a 3 m stop lane
    offsets = np.array([2.75, 6.25, 9.75, 13.25, 16.25])
    rings = np.concatenate([250.0 - offsets, 250.0 + offsets])
    angle = np.arctan2(v[:, 0], 250.0 - v[:, 1])
    inside = (angle > 0.01) & (angle < 1500 / 250 - 0.01) & (r > 200) & (r < 300)
    assert inside.sum() > 1000
    assert np.min(np.abs(r[inside, None] - rings), axis=1).max() < 0.03


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (None, "not well-formed XML"),  # truncated copy of a real file
        ("hello, not xml", "not well-formed XML"),
        ("<OpenDRIVE><header revMajor='1' revMinor='6'/></OpenDRIVE>", "has no <road>"),
        ("<OpenDRIVE><road id='7' length='10'><lanes/></road></OpenDRIVE>", "no planView"),
        ("<map/>", "not an OpenDRIVE file"),
    ],
)
def test_bad_opendrive_gives_one_line_and_no_file(tmp_path, content, words):
    src = tmp_path / "in" / "bad.xodr"
    src.parent.mkdir()
    if content is None:
        src.write_bytes((ALKS / "alks_road_straight.xodr").read_bytes()[:3000])
    else:
        src.write_text(content)
    out_dir = tmp_path / "out"
    with pytest.raises(HiyariError) as err:
        import_opendrive(src, out_dir / "bad.net.xml")
    message = str(err.value)
    assert words in message and "bad.xodr" in message and "\n" not in message
    assert not out_dir.exists() or list(out_dir.iterdir()) == []


def test_opendrive_without_drivable_lanes(tmp_path):
    root = _opendrive()
    road = _road(root, 1, 0.0, 0.0, 0.0, 50.0, ("line",), {0.0: ([], [-1])})
    for lane in road.iter("lane"):
        if lane.get("id") == "-1":
            lane.set("type", "sidewalk")
    src = _write(root, tmp_path / "footpath.xodr")
    with pytest.raises(HiyariError) as err:
        import_opendrive(src, tmp_path / "out" / "f.net.xml")
    assert "footpath.xodr" in str(err.value) and "\n" not in str(err.value)
    assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []
