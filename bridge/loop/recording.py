"""Record a closed-loop run: ground truth, each sensor's raw output and object list, the
fused tracks and the ego's status, one MCAP file per run (hiyari.bridge.record.recorder)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from hiyari import __version__
from hiyari.bridge.loop.stack.aeb import AEBStage
from hiyari.bridge.loop.stack.interfaces import EgoStack, EgoStep
from hiyari.bridge.loop.stack.perception_sensors import SensorPerception
from hiyari.bridge.record.recorder import Recorder, RecorderConfig, SensorMount
from hiyari.net.mesh.road_mesh import network_scene_mesh
from hiyari.net.road.network import RoadNetwork
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.outputs import CameraFrame, PointCloud, RadarDetections
from hiyari.sensors.radar.config import RadarConfig
from hiyari.sensors.rig import Sensor
from hiyari.traffic.collision import Collision
from hiyari.traffic.commands import SignalLink
from hiyari.traffic.world_state import WorldState


class StepRecorder:
    """An ``on_step`` callback for run_closed_loop that writes every step to ``recorder``."""

    def __init__(
        self,
        recorder: Recorder,
        stack: EgoStack,
        ego_id: str,
        signals: Callable[[], Mapping[str, str]] | None = None,
    ) -> None:
        self.recorder = recorder
        self.ego_id = ego_id
        self.signals = signals  # traffic light states now (Simulation.signal_states)
        self.perception = (
            stack.perception if isinstance(stack.perception, SensorPerception) else None
        )

    def __call__(self, world: WorldState, step: EgoStep, collisions: list[Collision]) -> None:
        rec = self.recorder
        env = None
        if self.perception is not None:
            env = self.perception.preset.environment_for(
                float(world.heading[world.index(self.ego_id)])
            )
        signals = self.signals() if self.signals is not None else None
        rec.write_world(world, self.ego_id, env, collisions, signals)
        if self.perception is not None:
            for raw in self.perception.last_raw:
                if isinstance(raw, PointCloud):
                    rec.write_point_cloud(raw)
                elif isinstance(raw, RadarDetections):
                    rec.write_radar(raw)
                elif isinstance(raw, CameraFrame):
                    rec.write_camera(raw)
        for ol in step.object_lists:
            rec.write_objects(ol)
        rec.write_objects(step.tracks)
        cmd = step.command
        speed = float(world.speed[world.index(self.ego_id)])
        rec.write_ego_status(
            world.time, speed, cmd.ttc, AEBStage(cmd.aeb_stage).name.lower(), cmd.accel
        )


def open_recorder(
    path: Path,
    metadata: Mapping[str, object],
    stack: EgoStack,
    network: RoadNetwork,
    signal_links: Sequence[SignalLink] = (),
    config: RecorderConfig | None = None,
) -> Recorder:
    """A Recorder with the run's ``metadata`` (and the toolkit version), sensor configs (with mounts), static road mesh (the
    sensors' scene mesh when the stack has one, else built from ``network``) and OSI road
    (lanes, boundaries, stationary objects, traffic lights) written."""
    rec = Recorder(
        path,
        metadata={**metadata, "toolkit_version": __version__},
        config=config,
    )
    perception = stack.perception
    if isinstance(perception, SensorPerception):
        for sensor in perception.rig.sensors:
            config = sensor.config
            rec.add_sensor_config(
                sensor.name,
                dataclasses.asdict(config) if dataclasses.is_dataclass(config) else str(config),
                _mount(sensor),
            )
    geometry = network.geometry
    if isinstance(perception, SensorPerception):
        mesh = perception.scene.static_mesh
    else:
        mesh = network_scene_mesh(network)
    rec.write_static_mesh(mesh)
    rec.write_road(geometry, mesh, signal_links)
    return rec


def _mount(sensor: Sensor) -> SensorMount:
    """The sensor's mount and fields of view (radians) for OSI."""
    c = sensor.config
    if isinstance(sensor.config, LidarConfig):
        kind, h = "lidar", c.horizontal_fov_deg
        v = max(c.elevations_deg) - min(c.elevations_deg)
    elif isinstance(sensor.config, RadarConfig):
        kind, h, v = "radar", c.h_fov_deg, c.v_fov_deg
    else:
        kind, h = "camera", c.horizontal_fov_deg
        v = math.degrees(2 * math.atan(math.tan(math.radians(h) / 2) * c.height_px / c.width_px))
    return SensorMount(kind, sensor.mount.sensor_to_ego(), math.radians(h), math.radians(v))
