"""Simulated seconds per wall second of the closed loop in city traffic, with the ego's
64-channel LiDAR at 10 Hz, radar at 20 Hz and camera at 30 Hz, next to the same SUMO run
without the ego stack (same network, demand, seed and step), in the same process.

SUMO steps at 0.025 s so that every sensor can fire at its own rate. Both runs warm up the
same number of simulated seconds untimed (traffic fills the network), then time the window.

Next to it, the physical limit of this machine: 1 / (SUMO step + raw Embree cast of the same
rays) per simulated second, the raw cast being one Embree query per LiDAR scan (10 Hz) and
radar cycle (20 Hz) of the rig's rays into one prebuilt scene holding the road and the actors
of the last step (nothing else; benchmarks/raw_cast.py, shared with benchmarks/judge.py); on
one thread, and with the rays in two threads.

Wall times on this shared 2-core machine swing with other load, so the CPU seconds per
simulated second of each part (process CPU, cast threads included) are printed too, with the
CPU limit 1 / (SUMO + raw cast CPU) and the load average. The loop's CPU is counted from its
second simulated second on: its first second also loads the compiled kernels (once per
process; printed apart), as the untimed first cast of each raw query does for the limit.

Run: .venv/bin/python benchmarks/closed_loop.py [--seconds 30]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from raw_cast import raw_cast_seconds, static_mesh

from hiyari.bridge.loop.execute import execute
from hiyari.bridge.loop.stack.interfaces import EgoStep
from hiyari.bridge.loop.toml_runs import preset_spec
from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.presets.scenarios import build_scenario
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.sensors.rig import SensorRig
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
WARM_S = 1.0  # simulated seconds of the loop before its CPU is counted


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
            # CPU of this process (cast threads included) from 1 simulated s after the first
            # stack step on (see the module docstring)
            first = counts.setdefault("first", [time.process_time(), world.time])
            if "clock" not in counts and world.time - first[1] >= WARM_S - 1e-9:
                counts["clock"] = [time.process_time(), world.time]
                counts["first_cpu"] = time.process_time() - first[0]
            clock = counts.get("clock")
            if clock is not None:
                counts["cpu"] = (time.process_time() - clock[0]) / max(world.time - clock[1], 1e-9)
            counts["world"] = world
            counts["veh"] = int(world.is_vehicle.sum())
            counts["ped"] = int(world.is_pedestrian.sum())
            for ol in step.object_lists:
                counts[ol.source] = counts.get(ol.source, 0) + 1

        res = execute(preset_spec(cs, Path(tmp) / "run"), on_step=on_step)
        network = build_scenario(cs, Path(tmp) / "limit").network
        raw = raw_cast_seconds(static_mesh(network), counts["world"], "ego", SensorRig.default())
        raw1, raw2, raw_cpu = raw.wall_1, raw.wall_2, raw.cpu_1
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
        f"the loop's first {WARM_S:g} simulated s (kernels loaded, not counted below): "
        f"{counts['first_cpu']:.2f} CPU s"
    )
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
