"""Seeded demand generation on any drivable network: fringe pairs, single roads, loops."""

from __future__ import annotations

import math

import pytest
from lxml import etree
from xodr_authoring import SINGLE, opendrive, road, write

from hiyari.bridge.cli.main import main
from hiyari.errors import HiyariError
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.traffic import DemandConfig, SimConfig, Simulation, write_demand


def test_same_seed_same_bytes_and_rates(intersection_net, tmp_path):
    cfg = DemandConfig(
        vehicles_per_hour=720,
        persons_per_hour=360,
        end=3600,
        seed=5,
        vehicle_mix={"car": 0.5, "truck": 0.5},
    )
    a = write_demand(intersection_net, tmp_path / "a.rou.xml", cfg).read_bytes()
    b = write_demand(intersection_net, tmp_path / "b.rou.xml", cfg).read_bytes()
    assert a == b
    c = write_demand(
        intersection_net, tmp_path / "c.rou.xml", DemandConfig(**{**cfg.__dict__, "seed": 6})
    ).read_bytes()
    assert a != c
    root = etree.fromstring(a)
    trips = root.findall("trip")
    persons = root.findall("person")
    # Poisson counts: 720 +- 4 sigma (sigma = sqrt(720) ~ 27), 360 +- 4 * 19
    assert abs(len(trips) - 720) < 110 and abs(len(persons) - 360) < 76
    types = {t.get("type") for t in trips}
    assert types == {"car", "truck"}
    departs = [float(t.get("depart")) for t in trips]
    assert departs == sorted(departs) and departs[-1] < 3600
    assert all(t.get("from") != t.get("to") for t in trips)


def test_bad_demand_refused(intersection_net, tmp_path):
    with pytest.raises(HiyariError, match="unknown vehicle type 'tank'"):
        write_demand(
            intersection_net, tmp_path / "x.rou.xml", DemandConfig(vehicle_mix={"tank": 1})
        )
    with pytest.raises(HiyariError, match=">= 0"):
        write_demand(intersection_net, tmp_path / "x.rou.xml", DemandConfig(vehicles_per_hour=-1))
    assert not (tmp_path / "x.rou.xml").exists()


def _loop_map(path):
    """A closed ring of two half circles (radius 100 m), one lane each way: no fringe at all."""
    root = opendrive()
    half = math.pi * 100.0
    for rid, start, other in ((1, (0.0, 0.0, 0.0), 2), (2, (0.0, 200.0, math.pi), 1)):
        road(root, rid, start, half, SINGLE, shape=("arc", 0.01), lane_links=True,
             links=[("predecessor", "road", other, "end"), ("successor", "road", other, "start")])  # fmt: skip
    return write(root, path)


def _single_road_map(path):
    """One 600 m road, one lane each way, nothing else: each direction is its own network."""
    root = opendrive()
    road(root, 7, (0.0, 0.0, 0.0), 600.0, SINGLE)
    return write(root, path)


def _run(net, routes, seconds):
    seen, last = {}, None
    with Simulation(SimConfig(net=net, routes=[routes], step_length=0.5, end_time=seconds)) as sim:
        for state in sim.run():
            for vid, edge in zip(state.ids.tolist(), state.edge.tolist(), strict=True):
                seen.setdefault(vid, set()).add(edge)
            last = state
    return seen, last


def test_loop_keeps_its_vehicles_on_the_road(tmp_path):
    net = import_opendrive(_loop_map(tmp_path / "loop.xodr"), tmp_path / "loop.net.xml")
    cfg = DemandConfig(vehicles_per_hour=720, persons_per_hour=0, end=120.0, seed=3)
    routes = write_demand(net, tmp_path / "loop.rou.xml", cfg)
    root = etree.parse(str(routes)).getroot()
    vehicles = root.findall("vehicle")
    assert len(vehicles) > 10 and not root.findall("trip")
    normal = [e.get("id") for e in etree.parse(str(net)).getroot().iter("edge")
              if not e.get("function")]  # fmt: skip
    rings = {sign: {e for e in normal if e.startswith("-") == sign} for sign in (True, False)}
    for v in vehicles:  # a closed route round one direction's ring, repeated for the run
        route = v.find("route")
        edges = route.get("edges").split()
        assert int(route.get("repeat")) >= 1 and set(edges) == rings[edges[0].startswith("-")]
    seen, last = _run(net, routes, 120.0)
    assert len(seen) == len(vehicles)  # every vehicle was inserted ...
    assert set(last.ids.tolist()) == set(seen)  # ... and none has left the ring
    directions = {e.startswith("-") for edges in seen.values() for e in edges if e in normal}
    assert directions == {True, False}


def test_single_carriageway_carries_both_directions(tmp_path):
    net = import_opendrive(_single_road_map(tmp_path / "one.xodr"), tmp_path / "one.net.xml")
    cfg = DemandConfig(vehicles_per_hour=900, persons_per_hour=0, end=90.0, seed=2)
    routes = write_demand(net, tmp_path / "one.rou.xml", cfg)
    trips = etree.parse(str(routes)).getroot().findall("trip")
    assert {(t.get("from"), t.get("to")) for t in trips} == {("-7", "-7"), ("7", "7")}
    seen, _ = _run(net, routes, 90.0)
    edges = set().union(*seen.values())
    assert {"-7", "7"} <= edges and len(seen) == len(trips)


def _garbage_length(text: str) -> str:
    """The net with the first lane of its first normal edge given length "x12"."""
    edge = text.index("<edge ", text.index("<edge ", 0))
    while "function=" in text[edge : text.index(">", edge)]:
        edge = text.index("<edge ", edge + 1)
    at = text.index('length="', edge) + len('length="')
    return text[:at] + "x" + text[at:]


@pytest.mark.parametrize(
    ("damage", "words"),
    [
        (lambda text: text[: len(text) // 2], "not well-formed XML"),
        (lambda text: _garbage_length(text), "unreadable edge or lane"),
    ],
    ids=["truncated", "garbage-length"],
)
def test_broken_net_gives_one_line(intersection_net, tmp_path, damage, words):
    bad = tmp_path / "bad.net.xml"
    bad.write_text(damage(intersection_net.read_text()))
    with pytest.raises(HiyariError) as err:
        write_demand(bad, tmp_path / "out.rou.xml", DemandConfig(vehicles_per_hour=300))
    assert words in str(err.value) and "bad.net.xml" in str(err.value)
    assert "\n" not in str(err.value) and not (tmp_path / "out.rou.xml").exists()


def test_sim_with_demand_on_a_garbage_lane_shape_is_one_line(intersection_net, tmp_path, capsys):
    bad = tmp_path / "shape.net.xml"
    text = intersection_net.read_text()
    start = text.index(' shape="', text.index("<lane ")) + len(' shape="')
    bad.write_text(text[:start] + "12,abc 5" + text[text.index('"', start) :])
    code = main(["sim", "-n", str(bad), "--vph", "300", "-d", "10", "-q"])
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1 and err.startswith("hiyari: error: ")
    assert "Traceback" not in err


def test_nan_rates_refused():
    with pytest.raises(HiyariError, match="finite"):
        DemandConfig(vehicles_per_hour=float("nan")).validate()
