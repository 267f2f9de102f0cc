"""The raw Embree cast floor of the sensor closed loop, shared by benchmarks/closed_loop.py and
benchmarks/judge.py (imported as a sibling module: a script's own folder is on sys.path).

One Embree query per sensor firing of the rig's rays into one prebuilt scene holding the static
mesh and the actors of one WorldState (the ego left out, as the sensors see the world), nothing
else: no actor-scene rebuilds and no work on the hits. The engine is the sensors' own, the
fastest measured by benchmarks/ray_engines.py: Embree packets of 8 rays called from compiled
code (sensors/scene/embree_native.py). LiDAR: every ray of a scan, one query
per scan at its rate (10 Hz by default); radar: every ray of a cycle, one query per cycle
(20 Hz). Camera (only when asked for): the camera recognises analytically and casts just a few
rays per frame (30 Hz), here as its two queries: 3 x 3 visibility rays per actor in its view
(aimed at the actor's centre; the camera's own fan over the actor's silhouette) and one
background ray per actor (into the same scene; the camera casts it at the road alone).

Run as a script it does nothing (``make bench`` runs every file in benchmarks/).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np

from hiyari.net.mesh.road_mesh import build_scene_mesh
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.net.road.network import RoadNetwork
from hiyari.sensors.camera.sensor import (
    BACKGROUND_RANGE_M,
    VISIBILITY_ACROSS,
    VISIBILITY_UP,
    Camera,
)
from hiyari.sensors.rig import SensorRig
from hiyari.sensors.scene.actor_shapes import ActorAppearance, build_actor_mesh
from hiyari.sensors.scene.embree_native import Device, TriangleScene
from hiyari.sensors.scene.ray_scene import CAST_CHUNK
from hiyari.traffic.world_state import WorldState

#: The sensors of closed_loop.py's floor (the camera's few rays left out there).
LIDAR_RADAR = ("lidar", "radar")


class RawCast(NamedTuple):
    """Seconds of raw casting per simulated second: wall on one thread, wall with the rays in
    two threads, CPU of the one-thread casts, process CPU of the two-thread casts (both
    threads)."""

    wall_1: float
    wall_2: float
    cpu_1: float
    cpu_2: float


#: One query: origins (n, 3), directions (n, 3), range (m), queries per simulated second.
Query = tuple[np.ndarray, np.ndarray, np.float32, float]


def static_mesh(network: RoadNetwork) -> SceneMesh:
    """The static mesh the runs' sensors cast into: the road without buildings, as
    SensorPerception.default_rig and WarmCache.scene build it."""
    return build_scene_mesh(network.geometry, buildings=False)


def rig_queries(
    rig: SensorRig, world: WorldState, ego_id: str, sensors: Sequence[str]
) -> list[Query]:
    """The queries of one simulated second's firings of the rig's ``sensors`` on the ego
    ``ego_id`` at ``world`` (see module docstring); empty queries are left out."""
    ego = world.pose_of(ego_id)
    out: list[Query] = []
    for sensor in rig.sensors:
        if sensor.name not in sensors:
            continue
        s2w = sensor.sensor_to_world(ego)
        if isinstance(sensor, Camera):
            out += _camera_queries(sensor, s2w, world, ego_id)
            continue
        d = (sensor.index.directions.astype(np.float64) @ s2w[:3, :3].T).astype(np.float32)
        o = np.empty_like(d)
        o[:] = s2w[:3, 3].astype(np.float32)
        out.append((o, d, np.float32(sensor.config.max_range_m), sensor.rate_hz))
    return out


def _camera_queries(camera: Camera, s2w: np.ndarray, world: WorldState, ego_id: str) -> list[Query]:
    """The camera's visibility and background queries of one frame (Camera.view's actors in
    view: ahead of the lens, within its range + 10 m)."""
    cam = s2w[:3, 3]
    rows = np.flatnonzero(world.ids != ego_id)
    rel = (world.xyz[rows] - cam) @ s2w[:3, :3]
    dist = np.linalg.norm(rel, axis=1)
    rows = rows[(rel[:, 0] > 0.5) & (dist < camera.config.max_range_m + 10)]
    if not len(rows):
        return []
    centre = world.xyz[rows] + np.c_[np.zeros((len(rows), 2)), world.height[rows] / 2]
    to = centre - cam
    length = np.linalg.norm(to, axis=1)
    dirs = (to / length[:, None]).astype(np.float32)
    origins = np.empty_like(dirs)
    origins[:] = cam.astype(np.float32)
    k = len(VISIBILITY_ACROSS) * len(VISIBILITY_UP)
    rate = camera.rate_hz
    return [
        (np.repeat(origins, k, 0), np.repeat(dirs, k, 0), np.float32(length.max() + 5.0), rate),
        (origins, dirs, np.float32(BACKGROUND_RANGE_M), rate),
    ]


def raw_cast_seconds(
    static: SceneMesh,
    world: WorldState,
    ego_id: str,
    rig: SensorRig,
    sensors: Sequence[str] = LIDAR_RADAR,
    repeats: int = 5,
) -> RawCast:
    """Seconds of the raw Embree casts of one simulated second of ``sensors``' rays into
    ``static`` plus ``world``'s actors: per query the fastest wall time and the least CPU time
    of ``repeats`` (after one untimed cast), times its rate, summed."""
    actors = build_actor_mesh(world, ActorAppearance(), world.ids == ego_id)
    both = SceneMesh.concatenate(
        [static, SceneMesh(actors.vertices.astype(np.float64), actors.faces, actors.material)]
    )
    scene = TriangleScene(Device(), both.vertices, both.faces)
    queries = rig_queries(rig, world, ego_id, sensors)
    pool = ThreadPoolExecutor(2)

    def one(o: np.ndarray, d: np.ndarray, r: np.float32) -> None:
        scene.intersect(o, d, r)

    def two(o: np.ndarray, d: np.ndarray, r: np.float32) -> None:
        fs = [
            pool.submit(scene.intersect, o[a : a + CAST_CHUNK], d[a : a + CAST_CHUNK], r)
            for a in range(0, len(d), CAST_CHUNK)
        ]
        for f in fs:
            f.result()

    def per_second(cast: Callable[..., None], clock: Callable[[], float]) -> float:
        """Seconds by ``clock`` of one simulated second of ``cast``s of every query."""
        total = 0.0
        for o, d, r, rate in queries:
            cast(o, d, r)
            t = []
            for _ in range(repeats):
                t0 = clock()
                cast(o, d, r)
                t.append(clock() - t0)
            total += min(t) * rate
        return total

    try:
        # thread_time: the one-thread casts run on this thread; process_time counts the pool's
        return RawCast(
            per_second(one, time.perf_counter),
            per_second(two, time.perf_counter),
            per_second(one, time.thread_time),
            per_second(two, time.process_time),
        )
    finally:
        pool.shutdown()
