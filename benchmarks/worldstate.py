"""Cost of Simulation + WorldState against bare libsumo stepping of the same city scenario.

A generated city grid with >= 100 vehicles and >= 200 pedestrians in the network during the
measured window, and one ego vehicle inserted after the warm-up on a long route across the city
(it stays in the network for the whole window). Runs:

  bare                 one libsumo.simulationStep per step, nothing read (the baseline);
  full state           every actor every step (getters; subscriptions) - the default;
  ego scope R m        the actors within R m of the ego (ReadScope; ScopeScan reads the
                       candidates' positions every step and every position now and then):
                       250 m covers the sensors (LiDAR 120 m, camera 200 m, radar) plus
                       margin, 310 m also the closed loop's 300 m ground-truth eye;
  ... + collisions     the same with contact detection on the state read.

The machine is shared with other work whose load changes by the second, so the runs are timed
side by side: every run is a process of its own with the same simulation (same files, seed,
warm-up and ego; reads do not change the traffic), and the timed window is stepped in blocks
of 10 steps, one block per run in turn, so all runs see the same load and the same traffic.
Costs are process CPU time. The table shows, per run, the median over the blocks of its cost
over the bare run's in the same block, and the interquartile range. Last, the floor of a
full-state read
through libsumo's C++ API (no Python at all: benchmarks/worldstate_floor.cpp against
eclipse-sumo's libsumocpp, same files and seed, bare and read blocks alternating), when g++ is
available.

Run: .venv/bin/python benchmarks/worldstate.py
"""

from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import os
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass
from multiprocessing.connection import Connection
from pathlib import Path

import numpy as np
import sumolib
from tqdm import tqdm

from hiyari.net.sumo.build import CityGridParams, build_city_grid
from hiyari.sumo_tools import sumo_home
from hiyari.traffic import DemandConfig, ReadScope, SimConfig, Simulation, write_demand

EGO = "ego"
BLOCK = 10  # steps per timed block


@dataclass(frozen=True)
class Case:
    """One benchmark configuration."""

    name: str
    read: bool
    collisions: bool = False
    mode: str = "getters"
    radius: float | None = None


CASES = (
    Case("bare libsumo.simulationStep", read=False),
    Case("full state (getters)", read=True),
    Case("full state (subscriptions)", read=True, mode="subscriptions"),
    Case("full state + collisions", read=True, collisions=True),
    Case("ego scope 250 m", read=True, radius=250.0),
    Case("ego scope 310 m", read=True, radius=310.0),
    Case("ego scope 310 m + collisions", read=True, collisions=True, radius=310.0),
)


def long_route(net: Path) -> list[str]:
    """A car route between the two most distant fringe edges of the network."""
    n = sumolib.net.readNet(str(net))
    cars = [e for e in n.getEdges() if e.allows("passenger") and not e.isSpecial()]
    starts = [e for e in cars if not e.getIncoming()]
    ends = [e for e in cars if not e.getOutgoing()]
    a, b = max(
        ((a, b) for a in starts for b in ends),
        key=lambda ab: math.dist(ab[0].getFromNode().getCoord(), ab[1].getToNode().getCoord()),
    )
    return [e.getID() for e in n.getShortestPath(a, b, vClass="passenger")[0]]


def worker(
    case: Case, net: Path, demand: Path, route: list[str], warm: float, conn: Connection
) -> None:
    """One run in its own process: warm up, insert the ego, then step one block per request
    and answer (CPU seconds, actors per step summed); at the end, the actor counts."""
    scope = ReadScope(EGO, case.radius) if case.radius else None
    cfg = SimConfig(net=net, routes=[demand], seed=1, read_mode=case.mode, read_scope=scope)
    with Simulation(cfg, detect_collisions=case.collisions) as sim:
        if case.read:
            for _ in sim.run(until=warm):
                pass  # the subscription path subscribes actors as they depart
        else:
            sim.run_bare(warm)
        sim.add_vehicle(EGO, route, "DEFAULT_VEHTYPE", "best", 5.0, 10.0, scripted=False)
        conn.send("ready")
        while conn.recv() == "block":
            rows = 0
            t0 = time.process_time()
            if case.read:
                for _ in range(BLOCK):
                    rows += len(sim.step())
            else:
                sim.run_bare(sim.time + BLOCK * cfg.step_length)
            conn.send((time.process_time() - t0, rows))
        full = sim.full_state
        if EGO not in full.ids:
            raise RuntimeError("the ego left the network inside the timed window")
        conn.send((int(full.is_vehicle.sum()), int(full.is_pedestrian.sum())))


def measure(net: Path, demand: Path, warm: float, window: float) -> tuple[dict, tuple]:
    """Per case the CPU seconds and actor rows of every block; the end's actor counts."""
    route = long_route(net)
    ctx = mp.get_context("spawn")
    runs = []
    for case in CASES:
        here, there = ctx.Pipe()
        p = ctx.Process(target=worker, args=(case, net, demand, route, warm, there))
        p.start()
        runs.append((case, here, p))
    for _, conn, _ in runs:
        if conn.recv() != "ready":
            raise RuntimeError("a benchmark run did not start")
    blocks = max(4, int(round(window / 0.1)) // BLOCK)
    out: dict[str, list[tuple[float, int]]] = {c.name: [] for c in CASES}
    for b in tqdm(range(blocks), desc="blocks", unit="block"):
        for k in range(len(runs)):  # rotate who goes first: no run always follows another
            case, conn, _ = runs[(b + k) % len(runs)]
            conn.send("block")
            out[case.name].append(conn.recv())
    counts = None
    for _, conn, p in runs:
        conn.send("stop")
        counts = conn.recv()
        p.join()
    return out, counts


def cpp_floor(net: Path, demand: Path, warm: float, measure: float, tmp: Path) -> str:
    """Build and run worldstate_floor.cpp; its result line, or why it did not run."""
    gxx = shutil.which("g++")
    sumo = sumo_home()
    lib = sumo / "lib64"
    if not lib.is_dir():
        lib = sumo / "lib"
    if gxx is None or not (sumo / "include" / "libsumo" / "libsumo.h").exists():
        return "skipped (needs g++ and eclipse-sumo's libsumo headers)"
    exe = tmp / "worldstate_floor"
    src = Path(__file__).with_name("worldstate_floor.cpp")
    cmd = [gxx, "-O2", "-std=c++17", f"-I{sumo / 'include'}", str(src), "-o", str(exe)]
    cmd += [f"-L{lib}", "-lsumocpp", f"-Wl,-rpath,{lib}"]
    build = subprocess.run(cmd, capture_output=True, text=True)
    if build.returncode != 0:
        return f"skipped (build failed: {build.stderr.strip().splitlines()[-1]})"
    env = {**os.environ, "SUMO_HOME": str(sumo)}
    args = [str(exe), str(net), str(demand), repr(warm), repr(measure)]
    out = subprocess.run(args, capture_output=True, text=True, env=env, check=True)
    return out.stdout.strip().splitlines()[-1]


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
        out, (nveh, nper) = measure(net, demand, args.warm, args.measure)
        floor = cpp_floor(net, demand, args.warm, args.measure, Path(tmp))
    bare = np.array([cpu for cpu, _ in out[CASES[0].name]])
    n = len(bare)
    print(
        f"city grid, {nveh} vehicles (ego included) and {nper} pedestrians in the network at "
        f"the end; {n * BLOCK} steps of 0.1 s timed per run"
    )
    head = f"{'run':30s} {'actors/step':>11s} {'steps/CPU-s':>11s} {'cost vs bare':>12s}"
    print(f"{head} {'IQR':>13s}")
    for case in CASES:
        cpu = np.array([c for c, _ in out[case.name]])
        q1, cost, q3 = np.percentile(cpu / bare - 1, [25, 50, 75])
        actors = f"{sum(r for _, r in out[case.name]) / (n * BLOCK):.0f}" if case.read else "-"
        span = f"{q1:+.0%}..{q3:+.0%}"
        print(
            f"{case.name:30s} {actors:>11s} {n * BLOCK / cpu.sum():11.0f} {cost:+12.0%} {span:>13s}"
        )
    print(f"full-state floor, libsumo C++ API, no Python: {floor}")


if __name__ == "__main__":
    main()
