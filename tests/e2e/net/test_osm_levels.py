"""A bridge over a street, written as OSM maps it (bridge=yes, layer=1, two nodes): the
import puts the bridge at its layer's height and the street below on the ground, and a car
crossing the bridge passes over the car below it with no contact, although their ground
rectangles overlap in plan view; a building beside the bridge stands on the ground."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import shapely
from lxml import etree
from osm_authoring import bridge_loop

from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.road_mesh import network_scene_mesh
from hiyari.net.road.network import RoadNetwork
from hiyari.net.sumo.osm import import_osm
from hiyari.net.sumo.osm.levels import LEVEL_HEIGHT
from hiyari.traffic import SimConfig, Simulation
from hiyari.traffic.collision import CollisionDetector


@pytest.fixture(scope="module")
def bridge_net(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bridge")
    doc = bridge_loop()
    return doc, import_osm(doc.write(folder / "bridge.osm"), folder / "bridge.net.xml")


def _lanes(network: RoadNetwork, way: int) -> list:
    """The car lanes of way ``way`` (both directions)."""
    return [ln for e in network.sumo.getEdges() if e.getID().lstrip("-").split("#")[0] == str(way)
            for ln in e.getLanes() if ln.allows("passenger")]  # fmt: skip


def _heights(net, way: int) -> dict[str, list[float]]:
    """Lane id -> the heights of its shape points (0 where the shape has no z), for the
    lanes of way ``way``."""
    root = etree.parse(str(net)).getroot()
    return {
        ln.get("id"): [float((p.split(",") + ["0"])[2]) for p in ln.get("shape").split()]
        for e in root.iter("edge")
        if e.get("id").lstrip("-").split("#")[0] == str(way)
        for ln in e.iter("lane")
    }


def test_the_bridge_is_up_the_street_below_on_the_ground(bridge_net):
    doc, net = bridge_net
    bridge, under = _heights(net, doc.ids["bridge"]), _heights(net, doc.ids["under"])
    assert len(bridge) == 4 and len(under) == 4  # a car lane and a sidewalk each way
    assert {z for lane in bridge.values() for z in lane} == {LEVEL_HEIGHT}
    assert {z for lane in under.values() for z in lane} == {0.0}
    for lane in _heights(net, doc.ids["south"]).values():  # the approach carries the ramp
        assert min(lane) < 1.0 and max(lane) == LEVEL_HEIGHT


def test_a_car_on_the_bridge_passes_over_the_car_below(bridge_net):
    doc, net = bridge_net
    network = RoadNetwork(net)
    # eastwards along Under Street, northwards over the bridge
    low, high = (next(ln for ln in _lanes(network, doc.ids[way]) if ln.getEdge().getID()[0] != "-")
                 for way in ("under", "bridge"))  # fmt: skip
    meet = shapely.LineString([p[:2] for p in low.getShape()]).intersection(
        shapely.LineString([p[:2] for p in high.getShape()])
    )
    assert meet.geom_type == "Point"  # in plan view the two lanes cross
    # both cars' centres 10.75 m before the crossing point at 10 m/s: their rectangles (SUMO's
    # default car, 5 m x 1.8 m) overlap in plan view for some 0.7 s
    at = {
        ln: shapely.LineString([p[:2] for p in ln.getShape()]).project(meet) for ln in (low, high)
    }
    flat, seen_2d, contacts, z = CollisionDetector(), 0, [], set()
    with Simulation(SimConfig(net=net, step_length=0.1, seed=1)) as sim:
        for vid, ln in (("low", low), ("high", high)):
            edge = ln.getEdge().getID()
            sim.add_vehicle(vid, (edge,), "DEFAULT_VEHTYPE", str(ln.getIndex()), at[ln] - 8.25, 10.0,
                            scripted=True)  # fmt: skip
            sim.set_speed(vid, 10.0)
        for state in sim.run(until=3.0):
            contacts += sim.collisions
            if len(state) == 2:
                z.add(tuple(sorted(zip(state.ids, np.round(state.xyz[:, 2], 2), strict=True))))
                ground = dataclasses.replace(state, xyz=state.xyz * [1.0, 1.0, 0.0])
                seen_2d += bool(flat.detect(ground))
    assert z == {(("high", LEVEL_HEIGHT), ("low", 0.0))}  # SUMO's 3-D positions, one per level
    assert seen_2d >= 5 and contacts == []


def test_a_building_beside_the_bridge_stands_on_the_ground(tmp_path):
    doc = bridge_loop()
    # 12 m high, 2 m east of the bridge's sidewalk and nearer to the bridge (at 6 m) than to
    # any street on the ground
    doc.building(8.0, 10.0, 14.0, 40.0, height="12")
    net = import_osm(doc.write(tmp_path / "b.osm"), tmp_path / "b.net.xml")
    mesh = network_scene_mesh(RoadNetwork(net))
    feet = mesh.vertices[np.unique(mesh.faces[mesh.material == Material.BUILDING])]
    assert sorted(set(np.round(feet[:, 2], 3))) == [0.0, 12.0]
