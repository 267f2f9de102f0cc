"""OpenDRIVE lane types: each lane gets the users its type means (one table, net and scene).

ALKS roads: per carriageway exactly the driving lanes are open to cars; the hard shoulder
(type ``stop``) is in the net and the scene, closed to traffic, and a scripted (broken-down)
car can stand on it. A town map: sidewalks come in by default and carry pedestrians; with
``all_lanes`` the verge types come in too, and no car ever drives on a sidewalk, border or
median lane.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from paths import SHARED
from xodr_authoring import opendrive, road, town_map, write

from hiyari.bridge.cli.main import main
from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.road_mesh import surface_material
from hiyari.net.road.geometry import LaneKind, RoadGeometry
from hiyari.net.sumo.lane_types import LANE_TYPES, LaneUse
from hiyari.net.sumo.opendrive import ImportOptions, import_opendrive
from hiyari.traffic import DemandConfig, SimConfig, Simulation, write_demand

DATA = SHARED / "data"
ALKS_ROADS = sorted((DATA / "openscenario" / "alks" / "road_networks").glob("*.xodr")) + sorted(
    (DATA / "opendrive" / "alks").glob("*.xodr")
)


@pytest.mark.parametrize("xodr", ALKS_ROADS, ids=[f"{f.parent.name}/{f.stem}" for f in ALKS_ROADS])
def test_alks_carriageways_open_only_driving_lanes_to_cars(tmp_path, xodr):
    g = RoadGeometry.from_net(import_opendrive(xodr, tmp_path / "alks.net.xml"))
    edges = [e for e in g.edges.values() if e.function == ""]
    assert len(edges) == 2  # one carriageway per direction
    for edge in edges:
        lanes = [g.lanes[i] for i in edge.lanes]
        for_cars = sorted(ln.odr_lane for ln in lanes if "passenger" in ln.allowed)
        driving = sorted(ln.odr_lane for ln in lanes if ln.odr_type == "driving")
        assert len(driving) == 3 and for_cars == driving
        shoulders = [ln for ln in lanes if ln.odr_type == "stop"]
        assert len(shoulders) == 1
        hard = shoulders[0]
        assert hard.kind == LaneKind.SHOULDER and hard.allowed == {"emergency", "authority"}
        assert abs(hard.odr_lane) == 6 and hard.odr_road == "0" and hard.width == 3.0
        # the outermost lane of its carriageway, paved like the driving lanes
        assert hard.index == 0 and surface_material(hard) == Material.ASPHALT
        assert all(ln.odr_lane * hard.odr_lane > 0 for ln in lanes)  # one side of the road


def test_alks_ten_minutes_of_traffic_never_use_the_shoulder(tmp_path):
    """10 simulated minutes at 3000 veh/h on the straight ALKS road: 0 vehicle-steps of
    ordinary traffic on the hard shoulder, while a scripted broken-down car stands on it."""
    net = import_opendrive(DATA / "opendrive" / "alks" / "alks_road_straight.xodr",
                           tmp_path / "straight.net.xml")  # fmt: skip
    g = RoadGeometry.from_net(net)
    shoulder = {ln.id for ln in g.lanes.values() if ln.odr_type == "stop"}
    driving = {ln.id for ln in g.lanes.values() if ln.odr_type == "driving"}
    hard = g.lanes["-0_0"]
    assert hard.id in shoulder
    demand = write_demand(
        net, tmp_path / "d.rou.xml",
        DemandConfig(vehicles_per_hour=3000, persons_per_hour=0, end=600.0, seed=4),
    )  # fmt: skip
    steps, used, moved = 0, set(), 0
    config = SimConfig(net=net, routes=[demand], step_length=0.5, end_time=600.0)
    with Simulation(config) as sim:
        sim.step()
        sim.add_vehicle("broken_down", ["-0"], "car", 1, 500.0, 0.0, scripted=True)
        x, y = 497.75, float(hard.centre[0, 1])  # rectangle centre on the shoulder
        for state in sim.run():
            if "broken_down" in state.ids:
                if moved:
                    k = list(state.ids).index("broken_down")
                    assert state.lane[k] == hard.id
                    assert np.allclose(state.xyz[k, :2], [x, y], atol=0.05)
                sim.move_vehicle("broken_down", x, y, 0.0, 4.5, speed=0.0)
                moved += 1
            ordinary = state.ids != "broken_down"
            lanes = state.lane[ordinary]
            assert not (set(lanes.tolist()) & shoulder)
            steps += int(ordinary.sum())
            used.update(lanes.tolist())
    assert moved > 1000 and steps > 100_000  # the figure is about real traffic
    assert driving <= used  # every driving lane carried traffic


def test_town_sidewalks_walk_by_default(tmp_path, capsys):
    net = import_opendrive(town_map(tmp_path / "town.xodr"), tmp_path / "town.net.xml")
    g = RoadGeometry.from_net(net)
    walks = [ln for ln in g.lanes.values() if ln.odr_type == "sidewalk"]
    assert len(walks) == 4 and all(ln.allowed == {"pedestrian"} for ln in walks)
    assert all(ln.kind == LaneKind.SIDEWALK for ln in walks)
    assert not [ln for ln in g.lanes.values() if ln.odr_type in ("border", "median")]
    out = tmp_path / "sim.json"
    code = main(["sim", "-n", str(net), "--pph", "300", "-d", "60", "-q", "--json", str(out)])
    assert code == 0
    summary = json.loads(out.read_text())
    assert summary["persons_seen"] >= 1 and summary["vehicles_seen"] == 0


def test_all_lanes_keeps_cars_off_sidewalks_borders_and_medians(tmp_path):
    net = import_opendrive(
        town_map(tmp_path / "town.xodr"), tmp_path / "all.net.xml", ImportOptions(all_lanes=True)
    )
    g = RoadGeometry.from_net(net)
    verge = {ln.id for ln in g.lanes.values() if ln.odr_type in ("border", "median")}
    walks = {ln.id for ln in g.lanes.values() if ln.odr_type == "sidewalk"}
    assert len(verge) == 8 and all(not g.lanes[i].allowed for i in verge)
    assert {surface_material(g.lanes[i]) for i in verge} == {Material.GRASS}
    assert {surface_material(g.lanes[i]) for i in walks} == {Material.CONCRETE}
    forbidden = verge | walks | {ln.id for ln in g.lanes.values() if ln.internal
                                 and "passenger" not in ln.allowed}  # fmt: skip
    demand = write_demand(
        net, tmp_path / "d.rou.xml",
        DemandConfig(vehicles_per_hour=1800, persons_per_hour=600, end=120.0, seed=3),
    )  # fmt: skip
    cars = persons = 0
    with Simulation(SimConfig(net=net, routes=[demand], step_length=0.5, end_time=120.0)) as sim:
        for state in sim.run():
            vehicles = ~state.is_pedestrian
            assert not (set(state.lane[vehicles].tolist()) & forbidden)
            cars += int(vehicles.sum())
            persons += int(state.is_pedestrian.sum())
    assert cars > 1000 and persons > 100


def test_lane_type_table_is_consistent():
    for name, t in LANE_TYPES.items():
        assert t.name == name
        if t.use == LaneUse.TRAFFIC:
            assert t.imported and t.allow and "pedestrian" not in t.allow
        if t.use in (LaneUse.SHOULDER, LaneUse.PARKING):
            assert t.imported and not {"passenger", "truck", "bus"} & set(t.allow)
        if t.use == LaneUse.VERGE:
            assert not t.imported and not t.allow
    assert LANE_TYPES["sidewalk"].allow == ("pedestrian",) and LANE_TYPES["sidewalk"].imported
    assert LANE_TYPES["biking"].allow == ("bicycle",)
    assert LANE_TYPES["border"].surface.value == "grass"


def test_lane_types_unknown_to_the_table_are_verge(tmp_path):
    root = opendrive()
    lanes = {1: ("driving", 3.5), -1: ("driving", 3.5), -2: ("fooLane", 2.0), 2: ("shared", 2.0)}
    road(root, 1, (0.0, 0.0, 0.0), 100.0, lanes)
    src = write(root, tmp_path / "unknown.xodr")
    g = RoadGeometry.from_net(import_opendrive(src, tmp_path / "u.net.xml"))
    assert sorted(ln.odr_type for ln in g.lanes.values()) == ["driving", "driving"]
    g = RoadGeometry.from_net(
        import_opendrive(src, tmp_path / "all.net.xml", ImportOptions(all_lanes=True))
    )
    odd = [ln for ln in g.lanes.values() if ln.odr_type in ("fooLane", "shared")]
    assert len(odd) == 2 and all(not ln.allowed and ln.kind == LaneKind.OTHER for ln in odd)
    assert {surface_material(ln) for ln in odd} == {Material.GRASS}
    assert not g.walking_areas  # nobody may walk there either
