"""Simulated seconds per wall second of the closed loop in city traffic, with the ego's
64-channel LiDAR at 10 Hz, radar at 20 Hz and camera at 30 Hz, next to the same SUMO run
without the ego stack (same network, demand, seed and step), in the same process.

SUMO steps at 0.025 s so that every sensor can fire at its own rate. Both runs warm up the
same number of simulated seconds untimed (traffic fills the network), then time the window.

Run: .venv/bin/python benchmarks/closed_loop.py [--seconds 30]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from hiyari.bridge.scenario.presets import build_scenario
from hiyari.bridge.scenario.run import RunOptions, run_concrete
from hiyari.bridge.scenario.toml_file import ConcreteScenario
from hiyari.traffic.commands import SPEED_MODE_DEFAULT
from hiyari.traffic.simulation import SimConfig, Simulation

PARAMS = {
    "vehicles_per_hour": 2400.0,
    "persons_per_hour": 2400.0,
    "ve0_kmh": 40.0,
    "warmup_s": 300.0,
}
STEP = 0.025


def bare(cs: ConcreteScenario, work: Path) -> tuple[float, int, int]:
    """The same SUMO run, ego driven by SUMO, no sensors or stack: (sim s / wall s, veh, ped)."""
    sc = build_scenario(cs, work)
    with Simulation(SimConfig(net=sc.net, routes=sc.routes, step_length=STEP, seed=cs.seed)) as sim:
        sim.fast_forward(sc.warmup)
        sc.insert(sim)
        sim.set_speed_mode(sc.ego_id, SPEED_MODE_DEFAULT)
        n = int(round(cs.duration / STEP))
        t0 = time.perf_counter()
        for _ in range(n):
            state = sim.step()
        wall = time.perf_counter() - t0
    return cs.duration / wall, int(state.is_vehicle.sum()), int(state.is_pedestrian.sum())


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
        base_rt, nveh, nper = bare(cs, Path(tmp) / "bare")
        counts = {}

        def on_step(world, step, collisions):
            counts["veh"] = int(world.is_vehicle.sum())
            counts["ped"] = int(world.is_pedestrian.sum())
            for ol in step.object_lists:
                counts[ol.source] = counts.get(ol.source, 0) + 1

        res = run_concrete(cs, RunOptions(), on_step=on_step)
    loop_rt = res.sim_seconds / res.wall_seconds
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
        f"closed loop runs {loop_rt:.2f}x real time (target >= 2); "
        f"{base_rt / loop_rt:.1f}x the cost of SUMO alone"
    )


if __name__ == "__main__":
    main()
