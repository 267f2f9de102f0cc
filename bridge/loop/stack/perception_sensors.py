"""Sensor perception: the ego's LiDAR, radar and camera ray-cast against the scene each at its
own rate, recognised into object lists (hiyari.sensors), under one disturbance preset."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from hiyari.kinematics import Pose
from hiyari.net.mesh.road_mesh import network_scene_mesh
from hiyari.net.road.network import RoadNetwork
from hiyari.sensors.camera.sensor import Camera
from hiyari.sensors.environment.presets import DisturbancePreset, disturbance_preset
from hiyari.sensors.outputs import CameraFrame, ObjectList, PointCloud, RadarDetections
from hiyari.sensors.rig import SensorRig
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.traffic.world_state import WorldState

RawOutput = PointCloud | RadarDetections | CameraFrame


class SensorPerception:
    """A SensorRig on the ego; ``last_raw`` keeps this step's raw outputs for recording."""

    def __init__(
        self,
        scene: RayScene,
        rig: SensorRig,
        preset: DisturbancePreset,
        ego_id: str,
        step: float,
        seed: int,
    ) -> None:
        self.scene = scene
        self.rig = rig
        self.preset = preset
        self.ego_id = ego_id
        self.step = step
        # one stream per sensor, keyed by its position in the default rig's order, so that
        # adding or removing a sensor does not change another's noise draws
        order = ("camera", "radar", "lidar")
        self.rngs = {
            s.name: np.random.default_rng([seed, order.index(s.name) if s.name in order else k + 3])
            for k, s in enumerate(rig.sensors)
        }
        self.last_raw: list[RawOutput] = []
        self.render_every = 0  # render every Nth camera frame as an image (0: never)
        self._camera_frames = 0
        scene.set_appearance(preset.appearance)

    @staticmethod
    def default_rig(
        network: RoadNetwork,
        sensors: Sequence[str],
        environment: str,
        step: float,
        seed: int,
        ego_id: str = "ego",
        buildings: bool = False,
        workers: int = 2,
        preset: DisturbancePreset | None = None,
    ) -> SensorPerception:
        """The default rig, only the sensors named in ``sensors``, on the road of ``network``
        under the disturbance preset ``environment``; the simulation steps every ``step`` s;
        ray casts split over ``workers`` threads (same results for any number); ``preset``:
        a disturbance made elsewhere (the scenario's environment) in place of the named one."""
        scene = RayScene(network_scene_mesh(network, buildings=buildings), workers=workers)
        rig = SensorRig.default()
        rig.sensors = [s for s in rig.sensors if s.name in sensors]
        if preset is None:
            preset = disturbance_preset(environment)
        return SensorPerception(scene, rig, preset, ego_id, step, seed)

    def perceive(self, world: WorldState, ego_row: int, ego: Pose) -> list[ObjectList]:
        """Object lists of the sensors due at this step (none when no sensor fires)."""
        self.last_raw = []
        due = self.rig.due(world.time, self.step)
        if not due:
            return []
        self.scene.update(world, self.ego_id)
        env = self.preset.environment_for(ego.heading)
        lists = []
        for sensor in due:
            if isinstance(sensor, Camera):
                # images cost ~50 ms each: only the frames a recording keeps are rendered
                self.rig.render_images = self.render_every > 0 and (
                    self._camera_frames % self.render_every == 0
                )
                self._camera_frames += 1
            raw, objects = self.rig.sense(
                sensor, self.scene, ego, world, env, self.rngs[sensor.name]
            )
            if raw is not None:
                self.last_raw.append(raw)
            lists.append(objects)
        return lists
