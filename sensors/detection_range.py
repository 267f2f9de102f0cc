"""Detection range per sensor and disturbance preset: the perception-disturbance table.

A target (pedestrian crossing, or a car showing its rear) stands in the ego's lane of a
straight road at increasing distances; at each distance LiDAR and radar scan and recognise,
and the camera's detection probability is evaluated. A sensor's detection range is the
far end of the unbroken run of distances at which the target is recognised (LiDAR, radar: an
object whose ground truth is the target; camera: probability >= 0.5), 0 when never.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hiyari.errors import HiyariError
from hiyari.sensors.camera.config import CameraConfig
from hiyari.sensors.camera.sensor import Camera
from hiyari.sensors.environment.presets import PRESETS, DisturbancePreset
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.outputs import ObjectList
from hiyari.sensors.radar.config import RadarConfig
from hiyari.sensors.radar.sensor import Radar
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, actor_world
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState

TARGETS = ("pedestrian", "car", "motorcycle", "obstacle")
"""Standard targets: a pedestrian crossing, a car ahead showing its rear, a motorcycle ahead,
and a stationary obstacle (a stalled car broadside across the lane, the ego at 60 km/h)."""
OBSTACLE_EGO_SPEED = 60.0 / 3.6
"""Ego speed toward the stationary obstacle, m/s (radar sees it closing)."""
SENSORS = ("lidar", "radar", "camera")
EGO_LANE_Y = -1.75
"""The ego drives along +x in the right lane of the two-lane StraightRoad (lane centre)."""
OCCLUDER_GAP_M = 8.0
"""The occluding parked truck stands this far in front of the target."""
OCCLUDER_CLEARANCE_M = 2.0
"""Nearer targets get no truck: it needs this much room in front of the ego."""


@dataclass(frozen=True)
class RangeStudy:
    """Sensors and distances of the detection-range sweep."""

    distances_m: tuple[float, ...] = tuple(np.arange(5.0, 150.01, 2.5))
    """Target distances from the ego centre, m (2.5 m bins as in the seed's LiDAR study)."""
    lidar: LidarConfig = field(
        default_factory=lambda: LidarConfig.preset("divp-ref").with_fov(60.0)
    )
    """LiDAR: the 64-channel pattern with the seed reference unit's threshold ('divp-ref');
    a forward sector keeps the sweep fast without changing what the target sees."""
    radar: RadarConfig = field(default_factory=lambda: RadarConfig.preset("narrow"))
    """Radar (the seed's narrow grid, meant for far targets ahead)."""
    camera: CameraConfig = field(default_factory=lambda: CameraConfig.preset("wide"))
    """Camera (the seed's 120 deg / 2 Mpix unit)."""
    lidar_mount: Mount = Mount(x=0.0, z=1.9)
    """Roof LiDAR."""
    radar_mount: Mount = Mount(x=2.3, z=0.5)
    """Front-bumper radar."""
    camera_mount: Mount = Mount(x=0.8, z=1.3)
    """Windscreen camera."""
    seed: int = 7
    """Seed of the noise (one Generator per distance)."""
    guard_rail: bool = False
    """Guard rails along both road edges (radar multipath needs a reflector)."""


def target_world(target: str, distance: float, occluder: bool) -> WorldState:
    """Ego at the origin of its lane, the target ``distance`` m ahead, optional occluder."""
    if target not in TARGETS:
        raise HiyariError(f"unknown target {target!r} (known: {', '.join(TARGETS)})")
    actors = [dict(id="ego", cls=ActorClass.CAR, x=0.0, y=EGO_LANE_Y)]
    if target == "pedestrian":
        actors.append(
            dict(
                id="target", cls=ActorClass.PEDESTRIAN, x=distance, y=EGO_LANE_Y, heading=np.pi / 2
            )
        )
    elif target == "obstacle":
        actors[0]["speed"] = OBSTACLE_EGO_SPEED
        actors.append(
            dict(id="target", cls=ActorClass.CAR, x=distance, y=EGO_LANE_Y, heading=np.pi / 2)
        )
    else:
        cls = ActorClass.MOTORCYCLE if target == "motorcycle" else ActorClass.CAR
        actors.append(dict(id="target", cls=cls, x=distance, y=EGO_LANE_Y))
    truck_length, truck_width = ActorClass.TRUCK.size.length, ActorClass.TRUCK.size.width
    ego_front = ActorClass.CAR.size.length / 2
    if occluder and distance - OCCLUDER_GAP_M - truck_length / 2 > ego_front + OCCLUDER_CLEARANCE_M:
        # the truck's right edge runs through the target's centre line: half of it is hidden
        actors.append(
            dict(
                id="occluder",
                cls=ActorClass.TRUCK,
                x=distance - OCCLUDER_GAP_M,
                y=EGO_LANE_Y + truck_width / 2,
            )
        )
    return actor_world(actors)


@dataclass(frozen=True, eq=False)
class Observation:
    """One frame of the sweep."""

    world: WorldState
    objects: dict[str, ObjectList]
    """Object list per sensor ('lidar', 'radar', 'camera')."""
    camera_probability: float
    """The camera's detection probability for the target (0 when out of view)."""

    def ghosts(self, sensor: str) -> int:
        """Objects of ``sensor`` with no real surface behind them (false detections: noise,
        rain ghosts, multipath; static-scene objects are not counted)."""
        return int(np.sum(self.objects[sensor].truth == ""))


class RangeSweep:
    """Builds the road scene and the sensors once; ``ranges`` runs one preset and target."""

    def __init__(self, study: RangeStudy | None = None) -> None:
        self.study = study or RangeStudy()
        road = StraightRoad(
            x0=-20.0, x1=max(self.study.distances_m) + 60.0, guard_rail=self.study.guard_rail
        )
        self.scene = RayScene(road.mesh())
        self.lidar = Lidar(self.study.lidar, self.study.lidar_mount)
        self.radar = Radar(self.study.radar, self.study.radar_mount)
        self.camera = Camera(self.study.camera, self.study.camera_mount)

    def observe(
        self, target: str, preset: DisturbancePreset, distance: float, seed: list[int]
    ) -> Observation:
        """One frame with the target ``distance`` m ahead: every sensor's object list (each
        sensor sees its own window soiling) and the camera's detection probability."""
        self.scene.set_appearance(preset.appearance)
        world = target_world(target, float(distance), preset.occluder)
        self.scene.update(world, "ego")
        ego = world.pose_of("ego")
        env = preset.environment_for(ego.heading)
        rng = np.random.default_rng([self.study.seed, *seed])
        _, lidar_objects = self.lidar.sense(self.scene, ego, world, env.for_sensor("lidar"), rng)
        _, radar_objects = self.radar.sense(self.scene, ego, world, env.for_sensor("radar"), rng)
        view = self.camera.view(self.scene, ego, world, env.for_sensor("camera"))
        _, camera_objects = self.camera.sense(self.scene, ego, world, env.for_sensor("camera"), rng)
        p = view.probability[world.ids[view.rows] == "target"]
        return Observation(
            world,
            {"lidar": lidar_objects, "radar": radar_objects, "camera": camera_objects},
            float(p.max()) if len(p) else 0.0,
        )

    def detected(self, target: str, preset: DisturbancePreset) -> dict[str, np.ndarray]:
        """(len(distances),) bool per sensor: target recognised at each distance."""
        out = {s: np.zeros(len(self.study.distances_m), bool) for s in SENSORS}
        for i, d in enumerate(self.study.distances_m):
            ob = self.observe(target, preset, float(d), [i])
            out["lidar"][i] = np.any(ob.objects["lidar"].truth == "target")
            out["radar"][i] = np.any(ob.objects["radar"].truth == "target")
            out["camera"][i] = ob.camera_probability >= 0.5
        return out

    def ranges(self, target: str, preset: DisturbancePreset) -> dict[str, float]:
        """Detection range per sensor, m (see ``far_limit``)."""
        dist = np.asarray(self.study.distances_m)
        return {s: far_limit(dist, hit) for s, hit in self.detected(target, preset).items()}


def far_limit(distances: np.ndarray, detected: np.ndarray) -> float:
    """End of the unbroken run of detections that starts at the nearest detected distance, m
    (0 when never detected); a lone detection beyond a miss does not extend it."""
    hits = np.flatnonzero(detected)
    if not len(hits):
        return 0.0
    run = hits[0]
    while run + 1 < len(detected) and detected[run + 1]:
        run += 1
    return float(distances[run])


def perception_table(
    presets: list[str] | None = None,
    targets: tuple[str, ...] = ("pedestrian", "car"),
    study: RangeStudy | None = None,
    progress: bool = True,
) -> list[dict]:
    """Rows of target, preset, and detection range per sensor (m)."""
    from tqdm import tqdm

    names = presets or [
        "clear",
        "rain",
        "fog",
        "night",
        "night_headlights",
        "backlight",
        "dark_clothing",
        "soiling_uniform",
        "soiling_spot",
        "occlusion",
    ]
    unknown = [n for n in names if n not in PRESETS]
    if unknown:
        raise HiyariError(
            f"unknown disturbance preset(s) {', '.join(unknown)} (known: {', '.join(PRESETS)})"
        )
    sweep = RangeSweep(study)
    rows = []
    jobs = [(t, n) for t in targets for n in names]
    for target, name in tqdm(jobs, desc="detection ranges", disable=not progress):
        r = sweep.ranges(target, PRESETS[name])
        rows.append({"target": target, "preset": name, **{f"{s}_m": r[s] for s in SENSORS}})
    return rows


def table_markdown(rows: list[dict]) -> str:
    """The table as Markdown: one line per preset, columns sensor x target."""
    targets = list(dict.fromkeys(r["target"] for r in rows))
    presets = list(dict.fromkeys(r["preset"] for r in rows))
    by = {(r["target"], r["preset"]): r for r in rows}
    head = "| preset | " + " | ".join(f"{t} {s}" for t in targets for s in SENSORS) + " |"
    sep = "|---|" + "---:|" * (len(targets) * len(SENSORS))
    lines = [head, sep]
    for p in presets:
        cells = [f"{by[(t, p)][f'{s}_m']:.1f}" for t in targets for s in SENSORS]
        lines.append(f"| {p} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
