"""Steps/s of Simulation + WorldState against bare libsumo stepping of the same scenario.

A generated city grid with >= 100 vehicles and >= 100 pedestrians in the network during the
measured window. All runs happen in this process, one after another, from the same files and
seed; each is warmed up untimed to the same simulation time first.

Run: .venv/bin/python benchmarks/worldstate.py
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from hiyari.net.sumo.build import CityGridParams, build_city_grid
from hiyari.traffic import DemandConfig, SimConfig, Simulation, write_demand


def bare(config: SimConfig, warm: float, measure: float) -> tuple[float, int, int]:
    """Bare stepping (one libsumo.simulationStep per step, nothing read); returns
    (steps/s, vehicles, persons) at the end."""
    with Simulation(config, detect_collisions=False) as sim:
        sim.run_bare(warm)
        n = int(round(measure / config.step_length))
        t0 = time.perf_counter()
        sim.run_bare(warm + measure)
        dt = time.perf_counter() - t0
        state = sim.state
        return n / dt, int(state.is_vehicle.sum()), int(state.is_pedestrian.sum())


def hiyari_run(config: SimConfig, warm: float, measure: float, collisions: bool) -> float:
    """Simulation.step (WorldState read, optionally collision detection); returns steps/s."""
    with Simulation(config, detect_collisions=collisions) as sim:
        for _ in sim.run(until=warm):
            pass
        n = int(round(measure / config.step_length))
        t0 = time.perf_counter()
        for _ in range(n):
            sim.step()
        return n / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--warm", type=float, default=300.0, help="untimed warm-up, s")
    ap.add_argument("--measure", type=float, default=120.0, help="timed window, s")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        net = build_city_grid(Path(tmp) / "city.net.xml", CityGridParams())
        demand = write_demand(
            net,
            Path(tmp) / "demand.rou.xml",
            DemandConfig(
                vehicles_per_hour=2400, persons_per_hour=2400, end=args.warm + args.measure, seed=1
            ),
        )
        base = SimConfig(net=net, routes=[demand], seed=1)
        bare_sps, nveh, nper = bare(base, args.warm, args.measure)
        rows = [("bare libsumo.simulationStep", bare_sps)]
        rows.append(
            ("Simulation + WorldState (getters)", hiyari_run(base, args.warm, args.measure, False))
        )
        sub = SimConfig(net=net, routes=[demand], seed=1, read_mode="subscriptions")
        rows.append(
            (
                "Simulation + WorldState (subscriptions)",
                hiyari_run(sub, args.warm, args.measure, False),
            )
        )
        rows.append(
            ("... getters + collision detection", hiyari_run(base, args.warm, args.measure, True))
        )
    print(f"city grid, {nveh} vehicles and {nper} pedestrians in the network at the end")
    print(f"{'run':42s} {'steps/s':>9s} {'cost vs bare':>13s}")
    for name, sps in rows:
        print(f"{name:42s} {sps:9.0f} {bare_sps / sps - 1:+12.0%}")


if __name__ == "__main__":
    main()
