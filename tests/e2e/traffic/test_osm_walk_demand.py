"""Generated persons on an imported map whose walkable network is in pieces: a town street with
sidewalks crossing a fast through road that has none. netconvert guesses no crossing over a
road faster than 50 km/h at an uncontrolled junction, so the street's west and east halves
are apart for walking while its car lanes lead on across the junction (as on a real town
extract, Kouvola in pyrosm's test file, where SUMO stopped at t = 111 s: "No connection found
between edge ... for person ...")."""

from __future__ import annotations

from lxml import etree
from osm_authoring import OsmDoc

from hiyari.net.sumo.osm import import_osm
from hiyari.traffic.demand import DemandConfig, write_demand
from hiyari.traffic.simulation import SimConfig, Simulation


def _town_street_over_a_fast_road(path):
    d = OsmDoc()
    a, j, b = d.node(-150, 0), d.node(0, 0), d.node(150, 0)
    s, n = d.node(0, -150), d.node(0, 150)
    street = d.way([a, j, b], highway="residential", name="Town Street", sidewalk="both")
    d.way([s, j, n], highway="primary", name="Through Road", maxspeed="80", sidewalk="no")
    return d.write(path), street


def test_persons_walk_only_between_edges_they_can_walk_between(tmp_path):
    src, street = _town_street_over_a_fast_road(tmp_path / "town.osm")
    net = import_osm(src, tmp_path / "town.net.xml")
    demand = DemandConfig(vehicles_per_hour=0, persons_per_hour=3600, end=60.0, seed=1)
    routes = write_demand(net, tmp_path / "d.rou.xml", demand)
    walks = [(w.get("from"), w.get("to")) for w in etree.parse(str(routes)).iter("walk")]
    # west half: way `street`'s first piece (#0) both ways; east half: its second piece (#1)
    half = {e: e.lstrip("-").split("#")[1] for pair in walks for e in pair}
    assert len(walks) > 30 and all(half[o] == half[d] for o, d in walks)
    assert {o.lstrip("-").split("#")[0] for o, _ in walks} == {str(street)}
    walked = set()
    with Simulation(SimConfig(net=net, routes=[routes], step_length=0.2, seed=1)) as sim:
        for state in sim.run(until=120.0):  # SUMO stopped here on a walk it cannot route
            walked.update(state.ids[state.is_pedestrian].tolist())
    assert len(walked) > 30
