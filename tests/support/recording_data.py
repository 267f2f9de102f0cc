"""Data for the recording, replay and fuzz tests: a real SUMO run plus sensor outputs built from its
ground truth (synthetic numbers: the sensor models are tested elsewhere; here only the
recording round trip matters), and the road mesh of the network.

The helpers are imported by test_recording_roundtrip.py and test_replay_browser.py; the tests
in this file check that the data is what those tests rely on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hiyari.bridge.record.recorder import Recorder, RecorderConfig
from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.outputs import (
    HIT_NONE,
    HIT_STATIC,
    CameraFrame,
    ObjectList,
    PointCloud,
    RadarDetections,
)
from hiyari.traffic import Collision, SimConfig, Simulation, WorldState

CREATED = "2026-01-01T00:00:00Z"  # fixed creation time: identical inputs give identical files


def road_mesh(net: Path) -> SceneMesh:
    """The network's scene mesh (hiyari.net.mesh.road_mesh), or four quads when it is unavailable."""
    try:
        from hiyari.net.mesh.road_mesh import build_scene_mesh
        from hiyari.net.road.geometry import RoadGeometry
    except ImportError:
        return quad_mesh()
    return build_scene_mesh(RoadGeometry.from_net(net))


def quad_mesh() -> SceneMesh:
    """Two crossing asphalt strips and two paint strips (a stand-in road)."""
    quads = [
        ((-150, -3.5), (150, 3.5), Material.ASPHALT),
        ((-3.5, -150), (3.5, 150), Material.ASPHALT),
        ((-150, -0.1), (150, 0.1), Material.LANE_PAINT),
        ((-0.1, -150), (0.1, 150), Material.LANE_PAINT),
    ]
    parts = []
    for (x0, y0), (x1, y1), mat in quads:
        z = 0.01 if mat == Material.LANE_PAINT else 0.0
        v = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], float)
        parts.append(
            SceneMesh(v, np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.full(2, mat, np.uint8))
        )
    return SceneMesh.concatenate(parts)


def ego_pose(state: WorldState, row: int, height: float = 1.8) -> np.ndarray:
    """4x4 pose of a sensor on the roof of actor ``row`` (x forward along its heading)."""
    c, s = math.cos(state.heading[row]), math.sin(state.heading[row])
    t = np.eye(4)
    t[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    t[:3, 3] = state.xyz[row] + [0.0, 0.0, height]
    return t


def to_sensor(t: np.ndarray, world: np.ndarray) -> np.ndarray:
    """World points (N, 3) into the frame whose pose is ``t``."""
    return (world - t[:3, 3]) @ t[:3, :3]


def synthetic_lidar(state: WorldState, row: int, rng: np.random.Generator) -> PointCloud:
    """Points on the actors within 40 m, on the ground around the ego, and a few ghosts."""
    t = ego_pose(state, row)
    near = np.flatnonzero(np.hypot(*(state.xyz[:, :2] - state.xyz[row, :2]).T) < 40.0)
    near = near[near != row]
    per = 30
    rows = np.repeat(near, per)
    u = rng.uniform(-0.5, 0.5, (len(rows), 3))
    pts_actor = (
        state.xyz[rows] + u * np.c_[state.length[rows], state.width[rows], np.zeros(len(rows))]
    )
    pts_actor[:, 2] += (u[:, 2] + 0.5) * state.height[rows]
    a = rng.uniform(0, 2 * np.pi, 400)
    r = rng.uniform(3, 30, 400)
    ground = state.xyz[row] + np.c_[r * np.cos(a), r * np.sin(a), np.zeros(400)]
    ghosts = state.xyz[row] + rng.uniform(-10, 10, (5, 3)) + [0, 0, 12]
    world = np.concatenate([pts_actor, ground, ghosts])
    hit = np.concatenate([rows, np.full(400, HIT_STATIC), np.full(5, HIT_NONE)]).astype(np.int32)
    xyz = to_sensor(t, world).astype(np.float32)
    rng_m = np.linalg.norm(xyz, axis=1).astype(np.float32)
    intensity = np.where(hit >= 0, 0.6, 0.1) + rng.uniform(0, 0.3, len(hit))
    return PointCloud(
        state.time, "top", t, xyz, intensity.astype(np.float32), rng_m, hit, state.ids.copy()
    )


def synthetic_radar(state: WorldState, row: int, rng: np.random.Generator) -> RadarDetections:
    """One detection per actor within 80 m plus one ghost (HIT_NONE)."""
    t = ego_pose(state, row, 0.5)
    near = np.flatnonzero(np.hypot(*(state.xyz[:, :2] - state.xyz[row, :2]).T) < 80.0)
    near = near[near != row]
    p = to_sensor(t, state.xyz[near] + [0, 0, 0.5])
    p = np.concatenate([p, [[25.0, -3.0, 0.0]]])
    rng_m = np.linalg.norm(p, axis=1)
    rel_v = np.concatenate([state.velocity[near] - state.velocity[row], [[0.0, 0.0]]])
    los = p[:, :2] / np.maximum(rng_m, 1e-9)[:, None]
    n = len(p)
    return RadarDetections(
        time=state.time,
        sensor="front",
        sensor_to_world=t,
        range=rng_m,
        range_rate=np.einsum("ij,ij->i", rel_v @ t[:2, :2], los),
        azimuth=np.arctan2(p[:, 1], p[:, 0]),
        elevation=np.arcsin(np.clip(p[:, 2] / np.maximum(rng_m, 1e-9), -1, 1)),
        snr_db=rng.uniform(10, 30, n),
        power_dbm=rng.uniform(-90, -60, n),
        hit=np.concatenate([near, [HIT_NONE]]).astype(np.int32),
        actor_ids=state.ids.copy(),
    )


def synthetic_objects(
    state: WorldState, row: int, source: str, rng: np.random.Generator
) -> ObjectList:
    """Actors within 50 m in the ego frame with noise, one false positive, unknown sizes for
    pedestrians and no velocity for the false positive."""
    t = ego_pose(state, row, 0.0)
    near = np.flatnonzero(np.hypot(*(state.xyz[:, :2] - state.xyz[row, :2]).T) < 50.0)
    near = near[near != row]
    pos = to_sensor(t, state.xyz[near]) + rng.normal(0, 0.2, (len(near), 3))
    vel = np.c_[(state.velocity[near] - state.velocity[row]) @ t[:2, :2], np.zeros(len(near))]
    size = np.c_[state.length[near], state.width[near], state.height[near]]
    size[state.is_pedestrian[near]] = np.nan
    return ObjectList(
        time=state.time,
        source=source,
        frame_to_world=t,
        object_id=np.concatenate([near, [9999]]).astype(np.int64),
        cls=np.concatenate([state.cls[near], [-1]]).astype(np.int8),
        position=np.concatenate([pos, [[15.0, 2.0, 0.0]]]),
        velocity=np.concatenate([vel, [[np.nan, np.nan, np.nan]]]),
        size=np.concatenate([size, [[np.nan, np.nan, np.nan]]]),
        confidence=np.concatenate([rng.uniform(0.5, 1.0, len(near)), [0.3]]),
        truth=np.concatenate([state.ids[near], [""]]).astype(object),
    )


def synthetic_camera(state: WorldState, row: int) -> CameraFrame:
    """A small RGB image (gradient with a block whose place depends on time)."""
    h, w = 48, 64
    img = np.zeros((h, w, 3), np.uint8)
    img[..., 0] = np.linspace(0, 255, w, dtype=np.uint8)[None, :]
    img[..., 1] = np.linspace(0, 255, h, dtype=np.uint8)[:, None]
    x = int(state.time * 10) % (w - 8)
    img[20:28, x : x + 8] = (255, 255, 255)
    k = np.array([[50.0, 0, w / 2], [0, 50.0, h / 2], [0, 0, 1]])
    return CameraFrame(
        state.time, "front", ego_pose(state, row, 1.4), img, k, np.array([-0.1, 0.01])
    )


@dataclass
class RecordedRun:
    """What a test run produced, next to the recording of it."""

    path: Path
    states: list[WorldState] = field(default_factory=list)
    ego: list[str | None] = field(default_factory=list)
    lidar: list[PointCloud] = field(default_factory=list)
    radar: list[RadarDetections] = field(default_factory=list)
    objects: list[ObjectList] = field(default_factory=list)
    camera: list[CameraFrame] = field(default_factory=list)
    status: list[tuple[float, float, float, str, float]] = field(default_factory=list)
    collisions: list[Collision] = field(default_factory=list)
    mesh: SceneMesh | None = None


def record_run(
    net: Path, routes: Path, out: Path, duration: float, config: RecorderConfig | None = None
) -> RecordedRun:
    """Run SUMO on ``net`` / ``routes`` and record ground truth, the first vehicle as ego, and
    its synthetic sensors (LiDAR and radar every step, objects every second step, camera every
    fifth), ego status and contacts."""
    run = RecordedRun(out, mesh=road_mesh(net))
    rng = np.random.default_rng(5)
    cfg = config or RecorderConfig(camera_format="png", creation_time=CREATED)
    env = {"precipitation_mm_h": 3.0, "fog_visibility_m": 500.0, "illuminance_lux": 300.0}
    ego_id: str | None = None
    meta = {"scenario": "test intersection", "seed": 3, "sensors": ["top", "front"]}
    with (
        Simulation(SimConfig(net=net, routes=[routes], seed=3)) as sim,
        Recorder(out, meta, cfg) as rec,
    ):
        rec.add_sensor_config("top", {"kind": "lidar", "channels": 16})
        rec.write_static_mesh(run.mesh)
        for step, state in enumerate(sim.run(until=duration)):
            if ego_id is None or not np.any(state.ids == ego_id):
                vehicles = state.ids[state.is_vehicle]
                ego_id = str(vehicles[0]) if len(vehicles) else None
            rec.write_world(state, ego_id, env, sim.collisions)
            run.states.append(state)
            run.ego.append(ego_id)
            run.collisions.extend(sim.collisions)
            if ego_id is None:
                continue
            row = state.index(ego_id)
            pc, det = synthetic_lidar(state, row, rng), synthetic_radar(state, row, rng)
            rec.write_point_cloud(pc)
            rec.write_radar(det)
            run.lidar.append(pc)
            run.radar.append(det)
            if step % 2 == 0:
                for source in ("fusion", "radar"):
                    objs = synthetic_objects(state, row, source, rng)
                    rec.write_objects(objs)
                    run.objects.append(objs)
            if step % 5 == 0:
                cam = synthetic_camera(state, row)
                rec.write_camera(cam)
                run.camera.append(cam)
            ahead = synthetic_objects(state, row, "fusion", rng)
            closing = ahead.position[:, 0] > 0
            ttc = float(np.min(ahead.position[closing, 0] / 10.0)) if closing.any() else math.inf
            aeb = (
                "full"
                if ttc < 1.0
                else "partial"
                if ttc < 1.6
                else "warning"
                if ttc < 2.6
                else "off"
            )
            status = (state.time, float(state.speed[row]), ttc, aeb, float(state.accel[row]))
            rec.write_ego_status(*status)
            run.status.append(status)
    return run
