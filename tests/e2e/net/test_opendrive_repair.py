"""OpenDRIVE that netconvert refuses but other tools read is repaired on a copy, each repair
named in one line; the user's file is never touched. Junction shapes are chosen so that SUMO's
junction logic agrees with the paths vehicles drive."""

from __future__ import annotations

import math

import pytest
from lxml import etree
from xodr_authoring import SINGLE, junction, opendrive, road, write

from hiyari.errors import HiyariError
from hiyari.net.road.geometry import RoadGeometry
from hiyari.net.sumo.junction_check import check_junctions
from hiyari.net.sumo.opendrive import ImportOptions, import_opendrive
from hiyari.net.sumo.opendrive_repair import repair_opendrive
from hiyari.sumo_tools import run_sumo_tool
from hiyari.traffic import DemandConfig, SimConfig, Simulation, write_demand

THREE = {-1: ("driving", 3.5), -2: ("driving", 3.5), -3: ("driving", 3.5)}
TWO = {-1: ("driving", 3.5), -2: ("driving", 3.5)}


def _quirky_map(path):
    """Road 1 (3 lanes) splits in direct junction 9 into road 2 (2 lanes, then a zero-curvature
    arc) and road 3 (1 lane, a spiral of constant curvature); a speed sign without type."""
    root = opendrive()
    r1 = road(root, 1, (0.0, 0.0, 0.0), 100.0, THREE, links=[("successor", "junction", 9, None)])
    signals = etree.SubElement(r1, "signals")
    etree.SubElement(signals, "signal", id="s1", s="50", t="-8", type="", dynamic="no")
    road(root, 2, (100.0, 0.0, 0.0), 120.0, TWO, shape=("arc", 0.0),
         links=[("predecessor", "junction", 9, None)])  # fmt: skip
    road(root, 3, (100.0, -7.0, 0.0), 80.0, {-1: ("driving", 3.5)}, shape=("spiral", -0.01, -0.01),
         links=[("predecessor", "junction", 9, None)])  # fmt: skip
    junction(root, 9, [
        (1, None, "start", [(-1, -1), (-2, -2)], {"linkedRoad": "2"}),
        (1, None, "start", [(-3, -1)], {"linkedRoad": "3"}),
    ], type="direct")  # fmt: skip
    return write(root, path)


def test_each_repair_is_one_line_naming_element_and_line(tmp_path):
    src = _quirky_map(tmp_path / "quirky.xodr")
    before, mtime = src.read_bytes(), src.stat().st_mtime_ns
    with pytest.raises(HiyariError):  # what netconvert alone makes of the file
        run_sumo_tool("netconvert", ["--opendrive-files", str(src), "-o",
                                     str(tmp_path / "plain.net.xml")], str(src))  # fmt: skip
    lines = src.read_text().splitlines()
    repairs = repair_opendrive(src, tmp_path / "copy.xodr")
    expected = {"<junction": 1, "<connection": 2, "<arc": 1, "<spiral": 1, "<signal": 1}
    found = {k: sum(1 for r in repairs if k in r.element) for k in expected}
    assert found == expected
    for r in repairs:
        tag = r.element[r.element.index("<") :].split()[0]
        assert tag in lines[r.line - 1]  # the line named is the element's line
        message = r.message(src)
        assert message.startswith(f"{src}:{r.line}: ") and "\n" not in message
    warnings: list[str] = []
    net = import_opendrive(src, tmp_path / "out" / "quirky.net.xml", warn=warnings.append)
    assert warnings == [r.message(src) for r in repairs]
    assert src.read_bytes() == before and src.stat().st_mtime_ns == mtime
    assert sorted(p.name for p in src.parent.iterdir()) == ["copy.xodr", "out", "quirky.xodr"]
    # the split carries traffic from road 1 into both roads of the direct junction
    demand = write_demand(net, tmp_path / "d.rou.xml",
                          DemandConfig(vehicles_per_hour=1800, persons_per_hour=0, end=90.0))  # fmt: skip
    reached = set()
    with Simulation(SimConfig(net=net, routes=[demand], step_length=0.5, end_time=90.0)) as sim:
        for state in sim.run():
            reached.update(state.edge.tolist())
    assert {"-1", "-2", "-3"} <= reached


def test_arc_of_zero_curvature_keeps_its_geometry(tmp_path):
    src = _quirky_map(tmp_path / "quirky.xodr")
    g = RoadGeometry.from_net(import_opendrive(src, tmp_path / "q.net.xml", warn=lambda m: None))
    lane = g.lanes["-2_0"]  # road 2, the outer lane: 5.25 m right of the straight line y = 0
    assert abs(lane.centre[:, 1] + 5.25).max() < 0.01
    assert lane.centre[0, 0] == pytest.approx(100.0, abs=2.0)
    assert lane.centre[-1, 0] == pytest.approx(220.0, abs=0.01)


def _crossless_junction(path):
    """Road 1 (two lanes) -> junction 100: straight on to road 2 (connecting road 101) and a
    right turn (radius 10 m) from the outer lane to road 3 (connecting road 102); road 2 back
    to road 1 on the left lane. No two connecting roads cross."""
    root = opendrive()
    road(root, 1, (0.0, 0.0, 0.0), 100.0, {1: ("driving", 3.5), -1: ("driving", 3.5),
         -2: ("driving", 3.5)}, links=[("successor", "junction", 100, None)])  # fmt: skip
    road(root, 2, (120.0, 0.0, 0.0), 100.0, SINGLE, links=[("predecessor", "junction", 100, None)])
    road(root, 3, (110.0 + 3.5, -10.0 - 3.5, -math.pi / 2), 100.0, {-1: ("driving", 3.5)},
         links=[("predecessor", "junction", 100, None)])  # fmt: skip
    road(root, 101, (100.0, 0.0, 0.0), 20.0, SINGLE, junction=100, lane_links=True,
         links=[("predecessor", "road", 1, "end"), ("successor", "road", 2, "start")])  # fmt: skip
    turn = road(root, 102, (100.0, -3.5, 0.0), math.pi / 2 * 10.0, {-1: ("driving", 3.5)},
                shape=("arc", -0.1), junction=100,
                links=[("predecessor", "road", 1, "end"), ("successor", "road", 3, "start")])  # fmt: skip
    lk = turn.find(".//lane[@id='-1']/link")
    for child in list(lk):
        lk.remove(child)
    etree.SubElement(lk, "predecessor", id="-2")
    etree.SubElement(lk, "successor", id="-1")
    junction(root, 100, [(1, 101, "start", [(-1, -1)], {}), (1, 102, "start", [(-2, -1)], {}),
                         (2, 101, "end", [(1, 1)], {})])  # fmt: skip
    return write(root, path)


def _content(net) -> bytes:
    """A net without netconvert's header comment (date, temporary file names)."""
    parser = etree.XMLParser(remove_comments=True)
    return etree.tostring(etree.parse(str(net), parser))


@pytest.mark.parametrize("shapes", [None, True, False], ids=["auto", "file", "computed"])
def test_junction_without_crossings_has_no_conflicts_and_no_collisions(tmp_path, shapes):
    src = _crossless_junction(tmp_path / "j.xodr")
    net = import_opendrive(src, tmp_path / "j.net.xml", ImportOptions(internal_shapes=shapes))
    assert check_junctions(net).clean
    root = etree.parse(str(net)).getroot()
    requests = [r for j in root.iter("junction") if j.get("id") == "100" for r in j.iter("request")]
    assert len(requests) == 3 and all(set(r.get("foes")) == {"0"} for r in requests)
    demand = write_demand(net, tmp_path / "d.rou.xml",
                          DemandConfig(vehicles_per_hour=2400, persons_per_hour=0, end=120.0))  # fmt: skip
    contacts, edges = set(), set()
    with Simulation(SimConfig(net=net, routes=[demand], step_length=0.25, end_time=120.0)) as sim:
        for state in sim.run():
            contacts.update((c.a, c.b) for c in sim.collisions)
            edges.update(state.edge.tolist())
    assert not contacts
    assert {"-2", "-3", "1"} <= edges  # straight on, the right turn, the other direction


def test_a_map_netconvert_rejects_with_one_junction_setting_falls_back(tmp_path, monkeypatch):
    """If netconvert fails with the file's junction shapes, the computed ones are used, with
    one warning line (the failure is provoked by an option netconvert rejects, for that run
    only); an explicit choice falls back too rather than losing the map."""
    import hiyari.net.sumo.opendrive as od

    src = _crossless_junction(tmp_path / "j.xodr")
    real = od._netconvert_args

    def broken_file_shapes(xodr, types, opts, shapes):
        args = real(xodr, types, opts, shapes)
        return [*args, "--no-such-option", "true"] if shapes else args

    monkeypatch.setattr(od, "_netconvert_args", broken_file_shapes)
    warnings: list[str] = []
    net = import_opendrive(src, tmp_path / "j.net.xml", warn=warnings.append)
    assert len(warnings) == 1 and "using netconvert's computed junction shapes" in warnings[0]
    assert str(src) in warnings[0] and "\n" not in warnings[0]
    assert check_junctions(net).clean
    explicit = import_opendrive(src, tmp_path / "k.net.xml", ImportOptions(internal_shapes=True),
                                warn=warnings.append)  # fmt: skip
    assert len(warnings) == 2 and _content(explicit) == _content(net)
    monkeypatch.setattr(od, "_netconvert_args", lambda *a: [*real(*a), "--no-such-option", "1"])
    with pytest.raises(HiyariError) as err:  # fails either way: one error, no output
        import_opendrive(src, tmp_path / "l.net.xml", warn=warnings.append)
    assert "j.xodr" in str(err.value) and "\n" not in str(err.value)
    assert not (tmp_path / "l.net.xml").exists()


def test_connecting_roads_not_marked_as_junction_roads(tmp_path):
    """Connecting roads written with junction="-1" become the junction's connecting roads
    (not ordinary roads crossing inside the junction without right-of-way rules)."""
    src = _crossless_junction(tmp_path / "j.xodr")
    root = etree.parse(str(src)).getroot()
    for r in root.iter("road"):
        if r.get("junction") == "100":
            r.set("junction", "-1")
    write(root, src)
    warnings: list[str] = []
    net = import_opendrive(src, tmp_path / "j.net.xml", warn=warnings.append)
    assert len(warnings) == 2
    assert all("connecting road of junction 100" in w for w in warnings)
    assert {w.split(": ")[1] for w in warnings} == {
        '<road id="101" junction="-1">',
        '<road id="102" junction="-1">',
    }
    g = RoadGeometry.from_net(net)
    normal = {e.id.lstrip("-").split("#")[0] for e in g.edges.values() if e.function == ""}
    assert normal == {"1", "2", "3"}  # 101 and 102 are lanes inside junction 100
