"""One frame of a scenario seen by one sensor under one disturbance preset, written to files.

The scenario is either the built-in street (synthetic_scenes.street_scenario on a straight
road) or a SUMO net run with libsumo up to a time, with the net's scene mesh from
hiyari.net.mesh.road_mesh and the ego a chosen (or the most central) vehicle.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hiyari.bridge.studies.report.perception.sensor_views import (
    plot_point_cloud,
    plot_radar,
    write_camera,
    write_objects_csv,
    write_point_cloud,
    write_radar_csv,
)
from hiyari.errors import HiyariError
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.camera.config import CameraConfig
from hiyari.sensors.camera.render import draw_objects
from hiyari.sensors.camera.sensor import Camera
from hiyari.sensors.environment.presets import disturbance_preset
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.radar.config import RadarConfig
from hiyari.sensors.radar.sensor import Radar
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, street_scenario
from hiyari.traffic.world_state import WorldState

SENSOR_KINDS = ("lidar", "radar", "camera")


@dataclass(frozen=True)
class FrameRequest:
    """What to render: sensor kind and presets, scenario source, output folder."""

    sensor: str = "lidar"
    preset: str = "clear"
    out: Path = Path("out/sensors")
    lidar_preset: str = "64ch"
    radar_preset: str = "narrow"
    camera_preset: str = "wide"
    net: Path | None = None
    routes: tuple[Path, ...] = ()
    vehicles_per_hour: float = 1800.0
    persons_per_hour: float = 1200.0
    time_s: float = 60.0
    ego: str | None = None
    seed: int = 1


def _sumo_frame(req: FrameRequest) -> tuple[SceneMesh, WorldState, str]:
    import tempfile

    from hiyari.net.mesh.road_mesh import network_scene_mesh
    from hiyari.net.road.network import RoadNetwork
    from hiyari.sumo_tools import check_net_loads
    from hiyari.traffic.demand import DemandConfig, write_demand
    from hiyari.traffic.simulation import SimConfig, Simulation

    if req.time_s <= 0:
        raise HiyariError(f"--time must be positive, got {req.time_s} s")
    check_net_loads(req.net)  # SUMO's own check first: its loader crashes on some broken nets
    mesh = network_scene_mesh(RoadNetwork(req.net), buildings=True)
    with tempfile.TemporaryDirectory(prefix="hiyari-sensors-") as tmp:
        routes = list(req.routes)
        generated = []
        if not routes:
            demand = DemandConfig(
                vehicles_per_hour=req.vehicles_per_hour,
                persons_per_hour=req.persons_per_hour,
                end=req.time_s + 60,
                seed=req.seed,
            )
            routes = generated = [write_demand(req.net, Path(tmp) / "demand.rou.xml", demand)]
        config = SimConfig(net=req.net, routes=routes, seed=req.seed, generated=generated)
        with Simulation(config) as sim:
            world = None
            for state in sim.run(until=req.time_s):
                world = state
    if world is None or not world.is_vehicle.any():
        raise HiyariError(
            f"no vehicle in the network at t={req.time_s} s: no ego to mount sensors on"
        )
    if req.ego is not None:
        if not np.any(world.ids == req.ego):
            raise HiyariError(f"--ego {req.ego!r} is not in the network at t={world.time} s")
        return mesh, world, req.ego
    veh = np.flatnonzero(world.is_vehicle)
    centre = mesh.vertices[:, :2].mean(0)
    return (
        mesh,
        world,
        str(world.ids[veh[np.argmin(np.linalg.norm(world.xyz[veh, :2] - centre, axis=1))]]),
    )


def render_sensor_frame(req: FrameRequest) -> list[Path]:
    """Render the frame and write raw output, object list and PNG view; returns the paths."""
    if req.sensor not in SENSOR_KINDS:
        raise HiyariError(f"unknown sensor {req.sensor!r} (known: {', '.join(SENSOR_KINDS)})")
    preset = disturbance_preset(req.preset)
    lidar_cfg = LidarConfig.preset(req.lidar_preset)
    radar_cfg = RadarConfig.preset(req.radar_preset)
    camera_cfg = CameraConfig.preset(req.camera_preset)
    if req.net is not None:
        mesh, world, ego_id = _sumo_frame(req)
        source = f"{Path(req.net).name} t={world.time:.1f} s"
    else:
        mesh, world, ego_id = StraightRoad().mesh(), street_scenario(preset.occluder), "ego"
        source = "built-in street"
    scene = RayScene(mesh, preset.appearance)
    scene.update(world, ego_id)
    ego = world.pose_of(ego_id)
    env = preset.environment_for(ego.heading)
    rng = np.random.default_rng(req.seed)
    out = Path(req.out)
    out.mkdir(parents=True, exist_ok=True)
    title = f"{req.sensor} - {req.preset} - {source}"
    if req.sensor == "lidar":
        lidar = Lidar(lidar_cfg, Mount(x=0.0, z=1.9))
        cloud, objects = lidar.sense(scene, ego, world, env, rng)
        return [
            write_point_cloud(cloud, out / "lidar_points.npz"),
            write_objects_csv(objects, out / "lidar_objects.csv"),
            plot_point_cloud(cloud, objects, out / "lidar.png", f"{title} ({len(cloud)} points)"),
        ]
    if req.sensor == "radar":
        radar = Radar(radar_cfg, Mount(x=2.3, z=0.5))
        det, objects = radar.sense(scene, ego, world, env, rng)
        return [
            write_radar_csv(det, out / "radar_detections.csv"),
            write_objects_csv(objects, out / "radar_objects.csv"),
            plot_radar(det, objects, out / "radar.png", f"{title} ({len(det)} detections)"),
        ]
    camera = Camera(camera_cfg, Mount(x=0.8, z=1.3))
    frame, objects = camera.sense(scene, ego, world, env, rng, render_image=True)
    return [
        *write_camera(frame, draw_objects(frame, objects, camera_cfg), out),
        write_objects_csv(objects, out / "camera_objects.csv"),
    ]
