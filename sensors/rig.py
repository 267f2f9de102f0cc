"""A sensor rig: sensors mounted on the ego, each firing at its own rate.

Closed-loop use (one SUMO step of ``step`` seconds)::

    rig = SensorRig.default()
    for sensor in rig.due(world.time, step):
        raw, objects = rig.sense(sensor, scene, ego, world, env, rng)

``raw`` is a PointCloud, RadarDetections or CameraFrame (None for a camera frame that was not
rendered), ``objects`` the sensor's ObjectList.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from hiyari.kinematics import Pose
from hiyari.sensors.camera.config import CameraConfig
from hiyari.sensors.camera.sensor import Camera
from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.outputs import CameraFrame, ObjectList, PointCloud, RadarDetections
from hiyari.sensors.radar.config import RadarConfig
from hiyari.sensors.radar.sensor import Radar
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.traffic.world_state import WorldState

Sensor = Lidar | Radar | Camera


@dataclass
class SensorRig:
    """Sensors on one ego vehicle; ``render_images`` makes cameras also render pictures."""

    sensors: list[Sensor] = field(default_factory=list)
    render_images: bool = False

    @staticmethod
    def default(
        lidar: str = "64ch",
        radar: str = "narrow",
        camera: str = "wide",
        render_images: bool = False,
    ) -> SensorRig:
        """Roof LiDAR (1.9 m), front-bumper radar (x 2.3 m, 0.5 m up), windscreen camera
        (x 0.8 m, 1.3 m up); presets by name."""
        return SensorRig(
            [
                Lidar(LidarConfig.preset(lidar), Mount(x=0.0, z=1.9), "lidar"),
                Radar(RadarConfig.preset(radar), Mount(x=2.3, z=0.5), "radar"),
                Camera(CameraConfig.preset(camera), Mount(x=0.8, z=1.3), "camera"),
            ],
            render_images,
        )

    def due(self, time: float, step: float) -> list[Sensor]:
        """Sensors with a sampling instant k / rate_hz in (time - step, time]."""
        eps = 1e-9
        out = []
        for s in self.sensors:
            if math.floor(time * s.rate_hz + eps) > math.floor((time - step) * s.rate_hz + eps):
                out.append(s)
        return out

    def sense(
        self,
        sensor: Sensor,
        scene: RayScene,
        ego: Pose,
        world: WorldState,
        env: Environment,
        rng: np.random.Generator,
    ) -> tuple[PointCloud | RadarDetections | CameraFrame | None, ObjectList]:
        """Raw output and object list of one sensor for this step."""
        if isinstance(sensor, Camera):
            return sensor.sense(scene, ego, world, env, rng, render_image=self.render_images)
        return sensor.sense(scene, ego, world, env, rng)
