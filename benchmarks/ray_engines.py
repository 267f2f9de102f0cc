"""Ray engines compared on the closed loop's own work: the rig's LiDAR (10 Hz), radar (20 Hz)
and camera (30 Hz) rays into the city scene, the actors' meshes replaced at every step a sensor
fires, as RayScene does (static road scene built once; an actor scene per step; every ray into
the static scene, then the rays that may reach an actor into the actor scene, limited to the
static hit distance).

Engines (each optional: left out with a note when its package is not installed):
  - embreex: today's engine (rtcIntersect1 per ray inside embreex, scenes copied in);
  - embree-1 / embree-8: the same Embree library called from compiled code
    (sensors/scene/embree_native.py), one ray or packets of 8 rays (rtcIntersect8), scenes
    built on shared buffers; embree-8-refit also refits the actor scene when the set of actors
    is unchanged instead of rebuilding it;
  - open3d: Open3D's RaycastingScene (PyPI open3d / open3d-cpu; no per-ray far limit, so its
    hits beyond the limit are dropped afterwards);
  - mitsuba: Mitsuba 3 on Dr.Jit's LLVM backend (llvm_ad_rgb; ray_intersect_preliminary).
Timed per engine, in seconds per simulated second: actor-scene builds, static casts and actor
casts (each engine's conversions in and out included); the work common to every engine (the
actor meshes placed, the rays that may reach an actor picked) is printed once. Every engine's
hits (static / actor / none and distance) are compared ray by ray with embreex's.

Each engine runs ``--repeats`` times, interleaved, on 1 thread and on 2 threads (embreex and
embree-*: chunks of 8,192 rays on a 2-thread pool, as RayScene; Open3D: ``nthreads``; Dr.Jit:
``set_thread_count``); the fastest repeat counts. CPU seconds (process) are printed next to
wall seconds: the machine is shared, and CPU is the figure robust to other load.

Run: .venv/bin/python benchmarks/ray_engines.py [--seconds 1] [--repeats 3]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh
from raw_cast import rig_queries, static_mesh

from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.presets.scenarios import build_scenario
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.camera.sensor import Camera
from hiyari.sensors.rig import SensorRig
from hiyari.sensors.scene import embree_native
from hiyari.sensors.scene.cast_kernel import actor_candidates
from hiyari.sensors.scene.ray_scene import CAST_CHUNK, RayScene, SensorRays
from hiyari.traffic.commands import SPEED_MODE_DEFAULT
from hiyari.traffic.simulation import SimConfig, Simulation
from hiyari.traffic.world_state import WorldState

PARAMS = {
    "vehicles_per_hour": 2400.0,
    "persons_per_hour": 2400.0,
    "ve0_kmh": 40.0,
    "warmup_s": 300.0,
}
STEP = 0.025
EGO = "ego"
Arr = np.ndarray


@dataclass
class Query:
    """One sensor firing's rays: origins, directions (N, 3) float32, range (m); the sensor's
    rays (to pick the rays that may reach an actor; None: all of them); static scene only."""

    origins: np.ndarray
    directions: np.ndarray
    max_range: np.float32
    rays: SensorRays | None
    static_only: bool = False
    bins: tuple[np.ndarray, ...] | None = None


@dataclass
class Frame:
    """One step at which a sensor fires: the actors' mesh and the due sensors' queries."""

    vertices: np.ndarray  # (V, 3) float32
    faces: np.ndarray  # (F, 3) int32
    key: bytes  # which actors, of which classes (equal keys: same triangles, moved)
    queries: list[Query] = field(default_factory=list)


def city_frames(seconds: float, tmp: Path) -> tuple[object, list[Frame], float]:
    """The city's static mesh, the frames of ``seconds`` simulated seconds after the warm-up,
    and the seconds spent on the common work (actor meshes placed, bins per sensor query)."""
    cs = ConcreteScenario("city", "ray engines", 0, 1, seconds, STEP, PARAMS, "sensors")
    preset = build_scenario(cs, tmp)
    static = static_mesh(preset.network)
    cfg = SimConfig(net=preset.network.path, routes=preset.routes, step_length=STEP, seed=1)
    worlds: list[WorldState] = []
    with Simulation(cfg) as sim:
        sim.fast_forward(preset.warmup)
        ScenarioEngine(preset.scenario, preset.roads, STEP).start(sim)
        sim.set_speed_mode(preset.scenario.ego, SPEED_MODE_DEFAULT)
        for _ in range(int(round(seconds / STEP))):
            worlds.append(sim.step())
    rig = SensorRig.default()
    # actors only: RayScene's bins of the rays that may reach an actor
    scene = RayScene(SceneMesh(np.zeros((0, 3)), np.zeros((0, 3), np.int32), np.zeros(0, np.uint8)))
    frames, common = [], 0.0
    for world in worlds:
        due = rig.due(world.time, STEP)
        if not due or EGO not in world.ids:
            continue
        t0 = time.process_time()
        scene.update(world, EGO)
        a = scene.actors
        _, first = np.unique(a.actor_row, return_index=True)
        rows = a.actor_row[np.sort(first)]
        key = "\0".join(world.ids[rows]).encode() + world.cls[rows].tobytes()
        frame = Frame(a.vertices, a.faces, key)
        ego = world.pose_of(EGO)
        for sensor in due:
            qs = rig_queries(SensorRig([sensor]), world, EGO, (sensor.name,))
            if isinstance(sensor, Camera):
                for k, (o, d, r, _) in enumerate(qs):
                    frame.queries.append(Query(o, d, r, None, static_only=k == 1))
                continue
            for o, d, r, _ in qs:
                s2w = sensor.sensor_to_world(ego)
                rays = SensorRays(sensor.index, s2w[:3, 3], s2w[:3, :3])
                q = Query(o, d, r, rays)
                q.bins = scene.actor_bins(rays, float(r))
                frame.queries.append(q)
        common += time.process_time() - t0
        frames.append(frame)
    return static, frames, common


# ---- engines: build(vertices, faces, actors) -> scene; cast(scene, o, d, tfar) -> prim, t ----


class Embreex:
    name = "embreex"

    def __init__(self) -> None:
        self.pool: ThreadPoolExecutor | None = None

    def threads(self, n: int) -> None:
        self.pool = ThreadPoolExecutor(n) if n > 1 else None

    def build(self, v: np.ndarray, f: np.ndarray, actors: bool, key: bytes = b"") -> object:
        scene = rtcore_scene.EmbreeScene()
        TriangleMesh(scene, v, f)
        scene.run(np.zeros((1, 3), np.float32), np.array([[0, 0, 1]], np.float32), dists=1e-3)
        return scene

    def _one(self, scene: Any, o: Arr, d: Arr, tfar: Arr) -> tuple[Arr, Arr]:
        r = scene.run(o, d, dists=tfar, output=1)
        return r["primID"], r["tfar"]

    def cast(self, scene: Any, o: Arr, d: Arr, tfar: Arr) -> tuple[Arr, Arr]:
        return chunked(self.pool, self._one, scene, o, d, tfar)


def chunked(
    pool: ThreadPoolExecutor | None, one: Callable, scene: Any, o: Arr, d: Arr, tfar: Arr
) -> tuple[Arr, Arr]:
    """``one`` over the rays in CAST_CHUNK chunks on ``pool`` (or in one go without it)."""
    n = len(d)
    if pool is None or n < 2 * CAST_CHUNK:
        return one(scene, o, d, tfar)
    prim = np.empty(n, np.int32)
    t = np.empty(n, np.float32)

    def part(a: int) -> None:
        b = min(a + CAST_CHUNK, n)
        prim[a:b], t[a:b] = one(scene, o[a:b], d[a:b], tfar[a:b])

    for f in [pool.submit(part, a) for a in range(0, n, CAST_CHUNK)]:
        f.result()
    return prim, t


class EmbreeNative(Embreex):
    def __init__(self, packets: bool, refit: bool = False) -> None:
        super().__init__()
        self.packets, self.refit = packets, refit
        self.name = f"embree-{8 if packets else 1}{'-refit' if refit else ''}"
        self.device = embree_native.Device()
        self.last: tuple[bytes, object] | None = None

    def build(self, v: Arr, f: Arr, actors: bool, key: bytes = b"") -> Any:
        if self.refit and actors and self.last is not None and self.last[0] == key:
            self.last[1].move(v)
            return self.last[1]
        scene = embree_native.TriangleScene(self.device, v, f, refit=self.refit and actors)
        if actors:
            self.last = (key, scene)
        return scene

    def _one(self, scene: Any, o: Arr, d: Arr, tfar: Arr) -> tuple[Arr, Arr]:
        prim, t, _ = scene.intersect(o, d, tfar, self.packets)
        return prim, t


class Open3D:
    name = "open3d"

    def __init__(self) -> None:
        import open3d as o3d

        self.o3d = o3d
        self.n = 1

    def threads(self, n: int) -> None:
        self.n = n

    def build(self, v: Arr, f: Arr, actors: bool, key: bytes = b"") -> Any:
        o3d = self.o3d
        scene = o3d.t.geometry.RaycastingScene(nthreads=self.n)
        scene.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f.astype(np.uint32)))
        return scene

    def cast(self, scene: Any, o: Arr, d: Arr, tfar: Arr) -> tuple[Arr, Arr]:
        rays = self.o3d.core.Tensor(np.hstack([o, d]))
        ans = scene.cast_rays(rays, nthreads=self.n)
        t = ans["t_hit"].numpy()
        prim = ans["primitive_ids"].numpy().astype(np.int32)
        miss = ~(t < tfar)
        prim[miss] = -1
        return prim, np.where(miss, tfar, t).astype(np.float32)


class Mitsuba:
    name = "mitsuba"

    def __init__(self) -> None:
        import drjit as dr
        import mitsuba as mi

        mi.set_variant("llvm_ad_rgb")
        self.mi, self.dr = mi, dr

    def threads(self, n: int) -> None:
        self.dr.set_thread_count(n)

    def build(self, v: Arr, f: Arr, actors: bool, key: bytes = b"") -> Any:
        mi = self.mi
        mesh = mi.Mesh("m", len(v), len(f))
        p = mi.traverse(mesh)
        p["vertex_positions"] = mi.Float(np.ascontiguousarray(v, np.float32).ravel())
        p["faces"] = mi.UInt(np.ascontiguousarray(f, np.uint32).ravel())
        p.update()
        return mi.load_dict({"type": "scene", "m": mesh})

    def cast(self, scene: Any, o: Arr, d: Arr, tfar: Arr) -> tuple[Arr, Arr]:
        mi = self.mi
        ray = mi.Ray3f(
            mi.Point3f(*(mi.Float(np.ascontiguousarray(o[:, k])) for k in range(3))),
            mi.Vector3f(*(mi.Float(np.ascontiguousarray(d[:, k])) for k in range(3))),
        )
        ray.maxt = mi.Float(tfar)
        pi = scene.ray_intersect_preliminary(ray, coherent=True)
        self.dr.eval(pi.t, pi.prim_index)
        t = pi.t.numpy()
        prim = pi.prim_index.numpy().astype(np.int64)
        miss = ~np.isfinite(t)
        prim = np.where(miss, -1, prim).astype(np.int32)
        return prim, np.where(miss, tfar, t).astype(np.float32)


@dataclass
class Timing:
    """Process CPU seconds per part and wall seconds of the whole pass."""

    build: float = 0.0
    static: float = 0.0
    actor: float = 0.0
    wall: float = 0.0

    @property
    def total(self) -> float:
        return self.build + self.static + self.actor


def run_engine(
    engine: Any, static_scene: Any, frames: list[Frame]
) -> tuple[Timing, list[np.ndarray]]:
    """One pass over the frames: the timing and per query (hit class, distance) per ray:
    class 0 none, 1 static, 2 actor."""
    tm = Timing()
    out = []
    clock = time.process_time
    w0 = time.perf_counter()
    for fr in frames:
        t0 = clock()
        actors = engine.build(fr.vertices, fr.faces, True, fr.key) if len(fr.faces) else None
        tm.build += clock() - t0
        for q in fr.queries:
            n = len(q.directions)
            t0 = clock()
            prim, t = engine.cast(
                static_scene, q.origins, q.directions, np.full(n, q.max_range, np.float32)
            )
            tm.static += clock() - t0
            dist = np.where(prim >= 0, t, np.inf).astype(np.float32)
            cls = (prim >= 0).astype(np.int8)
            if actors is not None and not q.static_only:
                if q.rays is None:
                    idx = np.arange(n)
                else:
                    idx = actor_candidates(dist, q.rays.index.bin, q.rays.index.elevation, q.bins)
                if len(idx):
                    lim = np.minimum(dist[idx], q.max_range).astype(np.float32)
                    o, d = (
                        np.ascontiguousarray(q.origins[idx]),
                        np.ascontiguousarray(q.directions[idx]),
                    )
                    t0 = clock()
                    pa, ta = engine.cast(actors, o, d, lim)
                    tm.actor += clock() - t0
                    hit = pa >= 0
                    dist[idx[hit]] = ta[hit]
                    cls[idx[hit]] = 2
            out.append(np.rec.fromarrays([cls, dist], names="cls,dist"))
    tm.wall = time.perf_counter() - w0
    return tm, out


def compare(ref: list[np.ndarray], other: list[np.ndarray]) -> tuple[float, int, int]:
    """Largest |distance difference| (m) over rays both hit in the same class, rays whose
    class differs, rays compared."""
    worst, differ, n = 0.0, 0, 0
    for a, b in zip(ref, other, strict=True):
        same = a.cls == b.cls
        differ += int((~same).sum())
        both = same & (a.cls > 0)
        if both.any():
            worst = max(worst, float(np.abs(a.dist[both] - b.dist[both]).max()))
        n += len(a)
    return worst, differ, n


def engines() -> tuple[list, list[str]]:
    out: list = [Embreex(), EmbreeNative(False), EmbreeNative(True), EmbreeNative(True, True)]
    missing = []
    for cls in (Open3D, Mitsuba):
        try:
            out.append(cls())
        except ImportError as exc:
            missing.append(f"{cls.name}: not installed ({exc})")
    return out, missing


def raw_lidar(eng: list, scenes: dict, q: Query, repeats: int) -> dict[str, tuple[float, float]]:
    """Per engine: least CPU and wall seconds of one LiDAR scan's rays into the static scene
    (after one untimed cast)."""
    out = {}
    tfar = np.full(len(q.directions), q.max_range, np.float32)
    for e in eng:
        e.cast(scenes[e.name], q.origins, q.directions, tfar)
        cpu, wall = [], []
        for _ in range(repeats):
            c0, w0 = time.process_time(), time.perf_counter()
            e.cast(scenes[e.name], q.origins, q.directions, tfar)
            cpu.append(time.process_time() - c0)
            wall.append(time.perf_counter() - w0)
        out[e.name] = (min(cpu), min(wall))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=1.0, help="simulated seconds of frames")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    load0 = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        static, frames, common = city_frames(args.seconds, Path(tmp))
    sim_s = args.seconds
    rays = sum(len(q.directions) for f in frames for q in f.queries)
    changes = sum(a.key != b.key for a, b in zip(frames, frames[1:], strict=False))
    lidar = max((q for f in frames for q in f.queries), key=lambda q: len(q.directions))
    eng, missing = engines()
    v32 = static.vertices.astype(np.float32)
    f32 = static.faces.astype(np.int32)
    best: dict[tuple[str, int], Timing] = {}
    raw: dict[int, dict[str, tuple[float, float]]] = {}
    hits: dict[str, list[np.ndarray]] = {}
    for threads in (1, 2):
        scenes = {}
        for e in eng:
            e.threads(threads)
            scenes[e.name] = e.build(v32, f32, False)
            run_engine(e, scenes[e.name], frames[:2])  # warm up (compilation, kernel caches)
        for _ in range(args.repeats):
            for e in eng:
                tm, h = run_engine(e, scenes[e.name], frames)
                key = (e.name, threads)
                if key not in best or tm.total < best[key].total:
                    best[key] = tm
                hits.setdefault(e.name, h)
        raw[threads] = raw_lidar(eng, scenes, lidar, args.repeats)
    load1 = os.getloadavg()
    print(
        f"city, {len(static.faces):,} static triangles (the loop's road mesh, no buildings); "
        f"{len(frames)} frames with a sensor due in {sim_s:g} simulated s ({rays:,} rays; "
        f"actor meshes of {np.mean([len(f.faces) for f in frames]):.0f} triangles on average, "
        f"the set of actors changed {changes} times)"
    )
    print(
        f"common to every engine (actor meshes placed, bins): {common / sim_s * 1e3:.0f} ms CPU "
        "per simulated s"
    )
    print(
        "CPU ms per simulated second (process CPU, fastest of the repeats), wall ms of the "
        "whole pass; x embreex: embreex's / this engine's (CPU on 1 thread, wall in 2 threads)"
    )
    print(
        f"{'engine':16s} {'thr':>3s} {'build':>7s} {'static':>7s} {'actor':>7s} {'CPU':>7s} "
        f"{'wall':>7s} {'x embreex':>9s} {'max |dt| m':>10s} {'differ':>7s}"
    )
    for threads in (1, 2):
        ref = best[("embreex", threads)]
        for e in eng:
            tm = best[(e.name, threads)]
            worst, differ, _ = compare(hits["embreex"], hits[e.name])
            ratio = ref.total / tm.total if threads == 1 else ref.wall / tm.wall
            print(
                f"{e.name:16s} {threads:3d} {tm.build / sim_s * 1e3:7.1f} "
                f"{tm.static / sim_s * 1e3:7.1f} {tm.actor / sim_s * 1e3:7.1f} "
                f"{tm.total / sim_s * 1e3:7.1f} {tm.wall / sim_s * 1e3:7.1f} "
                f"{ratio:9.2f} {worst:10.2e} {differ:7d}"
            )
    n = len(lidar.directions)
    print(f"one LiDAR scan ({n:,} rays) into the static scene alone, Mrays/s by CPU and by wall:")
    for e in eng:
        parts = []
        for threads in (1, 2):
            cpu, wall = raw[threads][e.name]
            parts.append(f"{threads} thr {n / cpu / 1e6:5.2f} CPU, {n / wall / 1e6:5.2f} wall")
        print(f"  {e.name:16s} " + "; ".join(parts))
    for m in missing:
        print(m)
    print(
        f"load average (1, 5, 15 min) before {load0[0]:.1f} {load0[1]:.1f} {load0[2]:.1f}, "
        f"after {load1[0]:.1f} {load1[1]:.1f} {load1[2]:.1f} on {os.cpu_count()} cores"
    )


if __name__ == "__main__":
    main()
