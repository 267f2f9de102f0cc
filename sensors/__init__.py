"""Ray-cast sensor models with perception disturbances: LiDAR, radar, camera, recognition.

Closed-loop use (build the scene once per network, update the actors every step)::

    from hiyari.sensors import Environment, RayScene, SensorRig, disturbance_preset
    scene = RayScene(static_mesh)                    # Embree BVH of the road, built once
    rig = SensorRig.default()                         # 64ch LiDAR 10 Hz, radar 20 Hz, camera 30 Hz
    preset = disturbance_preset("rain")               # or Environment(...) directly
    scene.set_appearance(preset.appearance)
    rng = np.random.default_rng(seed)
    for world in sim.run():
        scene.update(world, ego_id)                   # actor shapes only
        ego = world.pose_of(ego_id)                   # a hiyari.kinematics.Pose
        env = preset.environment_for(ego.heading)
        for sensor in rig.due(world.time, step):
            raw, objects = rig.sense(sensor, scene, ego, world, env, rng)

``raw`` is a PointCloud, RadarDetections or CameraFrame (None unless the rig renders images)
and ``objects`` an ObjectList with ground truth (sensors.outputs).
"""

from importlib import import_module

# Names load on first use, so that ``hiyari.sensors.outputs`` stays light for its readers.
_WHERE = {
    "ActorAppearance": "scene.actor_shapes",
    "Camera": "camera.sensor",
    "CameraConfig": "camera.config",
    "DisturbancePreset": "environment.presets",
    "Environment": "environment.conditions",
    "Illumination": "environment.conditions",
    "Lidar": "lidar.sensor",
    "LidarConfig": "lidar.config",
    "LidarRecognitionConfig": "lidar.recognition",
    "Mount": "frames",
    "PRESETS": "environment.presets",
    "Radar": "radar.sensor",
    "RadarConfig": "radar.config",
    "RadarRecognitionConfig": "radar.recognition",
    "RayScene": "scene.ray_scene",
    "SensorRig": "rig",
    "Soiling": "environment.conditions",
    "SoilingSpot": "environment.conditions",
    "disturbance_preset": "environment.presets",
    "recognise_lidar": "lidar.recognition",
    "recognise_radar": "radar.recognition",
    "sensor_to_world": "frames",
}
__all__ = sorted(_WHERE)


def __getattr__(name: str):
    if name in _WHERE:
        return getattr(import_module(f"hiyari.sensors.{_WHERE[name]}"), name)
    raise AttributeError(f"module 'hiyari.sensors' has no attribute {name!r}")
