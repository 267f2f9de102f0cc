"""Record a closed-loop run: ground truth, each sensor's raw output and object list, the
fused tracks and the ego's status, one MCAP file per run (hiyari.bridge.record.recorder)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from hiyari import __version__
from hiyari.bridge.record.recorder import Recorder
from hiyari.bridge.scenario.toml_file import ConcreteScenario
from hiyari.bridge.stack.aeb import AEBStage
from hiyari.bridge.stack.interfaces import EgoStack, EgoStep
from hiyari.bridge.stack.perception_sensors import SensorPerception
from hiyari.net.mesh.road_mesh import build_scene_mesh
from hiyari.net.road.network import RoadNetwork
from hiyari.sensors.outputs import CameraFrame, PointCloud, RadarDetections
from hiyari.traffic.collision import Collision
from hiyari.traffic.world_state import WorldState


class StepRecorder:
    """An ``on_step`` callback for run_closed_loop that writes every step to ``recorder``."""

    def __init__(self, recorder: Recorder, stack: EgoStack, ego_id: str) -> None:
        self.recorder = recorder
        self.ego_id = ego_id
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
        rec.write_world(world, self.ego_id, env, collisions)
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
    path: Path, cs: ConcreteScenario, stack: EgoStack, network: RoadNetwork
) -> Recorder:
    """A Recorder with the run's metadata, sensor configs and static road mesh written (the
    sensors' scene mesh when the stack has one, else built from ``network``)."""
    rec = Recorder(
        path,
        metadata={
            "scenario": cs.label(),
            "scenario_type": cs.type,
            "seed": cs.seed,
            "params": cs.params,
            "perception": cs.perception,
            "sensors": list(cs.sensors),
            "environment": cs.environment,
            "aeb_delay_s": cs.aeb_delay,
            "step_length_s": cs.step_length,
            "toolkit_version": __version__,
        },
    )
    perception = stack.perception
    if isinstance(perception, SensorPerception):
        for sensor in perception.rig.sensors:
            config = sensor.config
            rec.add_sensor_config(
                sensor.name,
                dataclasses.asdict(config) if dataclasses.is_dataclass(config) else str(config),
            )
        mesh = perception.scene.static_mesh
    else:
        mesh = build_scene_mesh(network.geometry)
    rec.write_static_mesh(mesh)
    return rec
