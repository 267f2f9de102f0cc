"""Simulated seconds per wall second of the closed loop in city traffic, with the ego's
64-channel LiDAR at 10 Hz, radar at 20 Hz and camera at 30 Hz, next to the same SUMO run
without the ego stack (same network, demand, seed and step), in the same process.

SUMO steps at 0.025 s so that every sensor can fire at its own rate. Both runs warm up the
same number of simulated seconds untimed (traffic fills the network), then time the window.

Next to it, the physical limit of this machine: 1 / (SUMO step + raw Embree cast of the same
rays) per simulated second, the raw cast being one Embree query per LiDAR scan (10 Hz) and
radar cycle (20 Hz) of the rig's rays into one prebuilt scene holding the road and the actors
of the last step (nothing else); on one thread, and with the rays in two threads.

Wall times on this shared 2-core machine swing with other load, so the CPU seconds per
simulated second of each part (process CPU, cast threads included) are printed too, with the
CPU limit 1 / (SUMO + raw cast CPU) and the load average.

Run: .venv/bin/python benchmarks/closed_loop.py [--seconds 30]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

from hiyari.bridge.scenario.engine import ScenarioEngine
from hiyari.bridge.scenario.presets import build_scenario
from hiyari.bridge.scenario.run import RunOptions, run_concrete
from hiyari.bridge.scenario.toml_file import ConcreteScenario
from hiyari.bridge.stack.interfaces import EgoStep
from hiyari.net.mesh.road_mesh import build_scene_mesh
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.net.road.network import RoadNetwork
from hiyari.sensors.rig import SensorRig
from hiyari.sensors.scene.actor_shapes import ActorAppearance, build_actor_mesh
from hiyari.sensors.scene.ray_scene import CAST_CHUNK
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


def bare(cs: ConcreteScenario, work: Path) -> tuple[float, float, int, int]:
    """The same SUMO run, ego driven by SUMO, no sensors or stack: (sim s / wall s, CPU s
    per sim s, vehicles, persons)."""
    preset = build_scenario(cs, work)
    cfg = SimConfig(net=preset.network.path, routes=preset.routes, step_length=STEP, seed=cs.seed)
    with Simulation(cfg) as sim:
        sim.fast_forward(preset.warmup)
        ScenarioEngine(preset.scenario, preset.roads, STEP).start(sim)
        sim.set_speed_mode(preset.scenario.ego, SPEED_MODE_DEFAULT)
        n = int(round(cs.duration / STEP))
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(n):
            state = sim.step()
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    nveh, nper = int(state.is_vehicle.sum()), int(state.is_pedestrian.sum())
    return cs.duration / wall, cpu / cs.duration, nveh, nper


def raw_cast_seconds(
    net: Path, world: WorldState, ego_id: str, repeats: int = 5
) -> tuple[float, float, float]:
    """Wall seconds of the raw Embree casts of one simulated second of the rig's LiDAR and
    radar rays (fastest of ``repeats``), on one thread and in two threads, and the CPU seconds
    of the one-thread casts (least of ``repeats``)."""
    mesh = build_scene_mesh(RoadNetwork(net).geometry, buildings=False)
    actors = build_actor_mesh(world, ActorAppearance(), world.ids == ego_id)
    both = SceneMesh.concatenate(
        [mesh, SceneMesh(actors.vertices.astype(np.float64), actors.faces, actors.material)]
    )
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, both.vertices.astype(np.float32), both.faces.astype(np.int32))
    ego = world.pose_of(ego_id)
    rig = SensorRig.default()
    bundles = []
    for sensor in rig.sensors:
        if hasattr(sensor, "index") and sensor.name in ("lidar", "radar"):
            s2w = sensor.sensor_to_world(ego)
            d = (sensor.index.directions.astype(np.float64) @ s2w[:3, :3].T).astype(np.float32)
            o = np.empty_like(d)
            o[:] = s2w[:3, 3].astype(np.float32)
            bundles.append((o, d, np.float32(sensor.config.max_range_m), sensor.rate_hz))
    pool = ThreadPoolExecutor(2)

    def one(o: np.ndarray, d: np.ndarray, r: np.float32) -> None:
        scene.run(o, d, dists=r, output=1)

    def two(o: np.ndarray, d: np.ndarray, r: np.float32) -> None:
        n = len(d)
        fs = [
            pool.submit(scene.run, o[a : a + CAST_CHUNK], d[a : a + CAST_CHUNK], dists=r, output=1)
            for a in range(0, n, CAST_CHUNK)
        ]
        for f in fs:
            f.result()

    out = []
    for cast, clock in (
        (one, time.perf_counter),
        (two, time.perf_counter),
        (one, time.thread_time),
    ):
        best = []
        for o, d, r, rate in bundles:
            cast(o, d, r)
            t = []
            for _ in range(repeats):
                t0 = clock()
                cast(o, d, r)
                t.append(clock() - t0)
            best.append(min(t) * rate)
        out.append(sum(best))
    pool.shutdown()
    return out[0], out[1], out[2]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=30.0, help="timed simulated seconds")
    args = ap.parse_args()
    cs = ConcreteScenario(
        "city",
        "benchmark city",
        0,
        1,
        args.seconds,
        STEP,
        PARAMS,
        perception="sensors",
        environment="clear",
    )
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        load0 = os.getloadavg()
        base_rt, base_cpu, nveh, nper = bare(cs, Path(tmp) / "bare")
        counts: dict = {}

        def on_step(world: WorldState, step: EgoStep, collisions: list) -> None:
            # CPU of this process (cast threads included) from the first stack step on
            clock = counts.setdefault("clock", [time.process_time(), world.time])
            counts["cpu"] = (time.process_time() - clock[0]) / max(world.time - clock[1], 1e-9)
            counts["world"] = world
            counts["veh"] = int(world.is_vehicle.sum())
            counts["ped"] = int(world.is_pedestrian.sum())
            for ol in step.object_lists:
                counts[ol.source] = counts.get(ol.source, 0) + 1

        res = run_concrete(cs, RunOptions(), on_step=on_step)
        net = build_scenario(cs, Path(tmp) / "limit").network.path
        raw1, raw2, raw_cpu = raw_cast_seconds(net, counts["world"], "ego")
        load1 = os.getloadavg()
    loop_rt = res.sim_seconds / res.wall_seconds
    sumo_s = 1.0 / base_rt  # wall seconds of SUMO + WorldState per simulated second
    print(
        f"city grid, {nveh} vehicles and {nper} pedestrians in the network (bare run end); "
        f"{args.seconds:.0f} s simulated, step {STEP} s"
    )
    print(
        f"sensor frames in the closed loop: LiDAR {counts.get('lidar', 0)}, "
        f"radar {counts.get('radar', 0)}, camera {counts.get('camera', 0)}"
    )
    print(f"{'run':44s} {'sim s / wall s':>15s}")
    print(f"{'SUMO + WorldState, no ego stack':44s} {base_rt:15.2f}")
    print(f"{'closed loop: LiDAR + radar + camera + fusion':44s} {loop_rt:15.2f}")
    print(
        f"{'physical limit 1 / (SUMO + raw Embree cast), 1 thread':44s} {1 / (sumo_s + raw1):15.2f}"
    )
    print(f"{'physical limit, raw cast in 2 threads':44s} {1 / (sumo_s + raw2):15.2f}")
    print(
        f"raw Embree cast per simulated second (LiDAR 10 Hz + radar 20 Hz rays): "
        f"{raw1 * 1e3:.0f} ms on 1 thread, {raw2 * 1e3:.0f} ms in 2 threads; "
        f"SUMO + WorldState {sumo_s * 1e3:.0f} ms"
    )
    loop_cpu = counts["cpu"]
    print(
        f"CPU s per simulated s (robust to other load; cast threads included): SUMO + WorldState "
        f"{base_cpu:.3f}, closed loop {loop_cpu:.3f} ({loop_cpu / base_cpu:.1f}x), raw Embree "
        f"cast {raw_cpu:.3f}; CPU limit 1 / (SUMO + raw cast) = {1 / (base_cpu + raw_cpu):.2f}, "
        f"the loop's CPU rate 1 / CPU = {1 / loop_cpu:.2f} ({(base_cpu + raw_cpu) / loop_cpu:.2f} "
        "of the limit)"
    )
    print(
        f"load average (1, 5, 15 min) before {load0[0]:.1f} {load0[1]:.1f} {load0[2]:.1f}, "
        f"after {load1[0]:.1f} {load1[1]:.1f} {load1[2]:.1f} on {os.cpu_count()} cores"
    )
    print(
        f"closed loop runs {loop_rt:.2f}x real time (target >= 5; baseline 1.9-2.5); "
        f"{base_rt / loop_rt:.1f}x the cost of SUMO alone; "
        f"{loop_rt * (sumo_s + raw1):.2f} of the 1-thread physical limit"
    )


if __name__ == "__main__":
    main()
