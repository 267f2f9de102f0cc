"""An imported OpenStreetMap town as the world: generated vehicles and pedestrians on real
SUMO (sidewalks, crossings, the signalised junction), its mapped buildings in the sensors'
scene (a LiDAR sees the tall building at its mapped distance and a pedestrian behind it is
hidden), and a closed-loop city run on it whose recording carries the buildings."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from osm_authoring import town
from runs import run_preset

from hiyari.bridge.loop.execute import RunOptions
from hiyari.bridge.openscenario.presets.scenarios import World
from hiyari.bridge.openscenario.presets.toml_file import parse_scenario
from hiyari.bridge.record.reader import Recording
from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.road_mesh import network_scene_mesh
from hiyari.net.road.geometry import LaneKind, RoadGeometry
from hiyari.net.road.network import RoadNetwork
from hiyari.net.sumo.osm import import_osm
from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.outputs import HIT_STATIC
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import actor_world
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.demand import DemandConfig, write_demand
from hiyari.traffic.simulation import SimConfig, Simulation


@pytest.fixture(scope="module")
def town_world(tmp_path_factory):
    folder = tmp_path_factory.mktemp("town")
    doc = town()
    net = import_osm(doc.write(folder / "town.osm"), folder / "town.net.xml")
    return doc, RoadNetwork(net)


def test_generated_traffic_walks_sidewalks_and_crossings(town_world, tmp_path):
    _, network = town_world
    g = RoadGeometry.from_net(network.path)
    kind = {lane_id: ln.kind for lane_id, ln in g.lanes.items()}
    demand = DemandConfig(vehicles_per_hour=900, persons_per_hour=1200, end=120.0, seed=3)
    routes = write_demand(network.path, tmp_path / "demand.rou.xml", demand)
    cfg = SimConfig(net=network.path, routes=[routes], step_length=0.1, seed=3)
    vehicles, persons, walked = set(), set(), set()
    car_contacts = []
    with Simulation(cfg) as sim:
        for state in sim.run(until=120.0):
            ped = state.is_pedestrian
            vehicles.update(state.ids[~ped].tolist())
            persons.update(state.ids[ped].tolist())
            walked.update(kind.get(lane) for lane in state.lane[ped])
            car_contacts += [c for c in sim.collisions if c.kind == "vehicle-vehicle"]
            # every vehicle drives on a lane vehicles may use
            on = [kind.get(lane) for lane in state.lane[~ped] if not lane.startswith(":")]
            assert set(on) <= {LaneKind.DRIVING}
    assert len(vehicles) > 20 and len(persons) > 20
    # people walk the sidewalks, the walking areas and cross the streets at the crossings
    assert {LaneKind.SIDEWALK, LaneKind.WALKINGAREA, LaneKind.CROSSING} <= walked
    assert not car_contacts


def _tall(doc, network: RoadNetwork):
    e = np.array(network.sumo.getNode(str(doc.ids["E"])).getCoord()[:2])
    tall = next(b for b in network.buildings if b.id == str(doc.ids["tall"]))
    return e, tall


def test_lidar_sees_the_mapped_building_and_not_who_is_behind_it(town_world):
    doc, network = town_world
    scene = RayScene(network_scene_mesh(network))
    e, tall = _tall(doc, network)
    # the ego on Main Street 40 m east of the signal, facing the tall building's south wall
    ego_xy = e + [40.0, 0.0]
    wall = shapely.Polygon(tall.outline).intersection(
        shapely.LineString([ego_xy, ego_xy + [0.0, 100.0]])
    )
    expected = wall.bounds[1] - ego_xy[1]  # about 20 m: the wall at y = E + 20 m
    assert expected == pytest.approx(20.0, abs=1.0)
    origins = np.array([[*ego_xy, 1.0], [*ego_xy, 12.5]], np.float32)
    north = np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]], np.float32)
    hits = scene.cast(origins, north, 200.0)
    assert hits.material[0] == Material.BUILDING
    assert hits.distance[0] == pytest.approx(expected, abs=0.05)
    assert not hits.distance[1] < 100.0  # 12.5 m up the ray passes over the 12 m roof

    hidden = e + [40.0, 70.0]  # north of the building
    seen = e + [80.0, 30.0]  # north-east, in the open: the line of sight misses the building
    world = actor_world(
        [
            dict(id="ego", cls=ActorClass.CAR, x=ego_xy[0], y=ego_xy[1]),
            dict(id="hidden", cls=ActorClass.PEDESTRIAN, x=hidden[0], y=hidden[1]),
            dict(id="seen", cls=ActorClass.PEDESTRIAN, x=seen[0], y=seen[1]),
        ]
    )
    scene.update(world, "ego")
    config = LidarConfig("ring", (0.0,), 3600, horizontal_fov_deg=360.0, rate_hz=10.0,
                         max_range_m=200.0, min_range_m=0.5, range_10pct_m=80.0,
                         range_noise_m=0.0)  # fmt: skip
    cloud = Lidar(config, Mount(z=1.0)).scan(
        scene, world.pose_of("ego"), world, Environment(), np.random.default_rng(0)
    )
    ids = cloud.truth_ids()
    assert (ids == "seen").sum() > 0 and (ids == "hidden").sum() == 0
    # straight north the scan ends on the wall
    az = np.degrees(np.arctan2(cloud.xyz[:, 1], cloud.xyz[:, 0]))
    north_pts = np.abs(az - 90.0) < 0.2
    assert north_pts.any() and (cloud.hit[north_pts] == HIT_STATIC).all()
    assert cloud.range[north_pts] == pytest.approx(expected, abs=0.1)


def test_city_run_on_the_imported_map_records_its_buildings(town_world, tmp_path):
    _, network = town_world
    logical = parse_scenario(
        {"scenario": {"type": "city", "duration": 4.0, "step_length": 0.1},
         "parameters": {"warmup_s": 5.0, "vehicles_per_hour": 600, "persons_per_hour": 600}},
        "city.toml",
    )  # fmt: skip
    (cs,) = logical.expand()
    out = tmp_path / "run"
    result = run_preset(cs, RunOptions(out_dir=out, record=True), world=World.of_net(network.path))
    assert result.sim_seconds > 0 and not result.collision
    mesh = Recording.open(out / "run.mcap").mesh()
    assert (mesh.material == Material.BUILDING).sum() == 24  # the two mapped buildings, closed
