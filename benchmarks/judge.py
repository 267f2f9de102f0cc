"""R157 points judged with the full sensor stack (camera + radar + LiDAR) on 2 workers: the
per-run path (road, scene and SUMO built for every point, every run simulated to its full
duration) against the judge's default path (road, Embree scene and rig built once per worker;
a run ends once its judged values cannot change), in the same run, on the same points.

Target (issue 16): >= 4 points/s on 2 workers, with verdicts identical to the per-run path.
Also printed: where a point's time goes, CPU seconds per point (robust to other load on the
machine; 2 / that is the rate 2 idle cores would give), and the rate at the closed loop's own
cost: workers / (simulated seconds per point x the loop's CPU per simulated second) (the
current cost, not a limit).

The floor, measured after the judge in this process on the same points: workers / (simulated
seconds per point as judged x (bare SUMO + raw cast) CPU seconds per simulated second), with
the raw cast on 1 thread and in 2 threads (also with the lead-in + manoeuvre alone as the
simulated seconds per point). It includes, per simulated second:
  - bare SUMO: libsumo simulationStep alone (Simulation.run_bare, nothing read) of each point's
    run at the judge's step, from its first state over the point's full duration (its vehicles
    inserted by the ScenarioEngine, then left to SUMO), CPU summed over the points;
  - raw Embree cast (benchmarks/raw_cast.py) of the judge's rig (the default rig with the
    judge's sensors, as its WarmCache builds it): one query per LiDAR scan (10 Hz, 64 x 2,048
    rays) and per radar cycle (20 Hz, 2,356 rays), and the camera's own few rays (30 Hz, two
    queries a frame: 3 x 3 visibility rays aimed at the centre of each actor in its view and
    1 background ray per such actor; the camera recognises analytically and renders no image
    in the judge), into one prebuilt scene of the R157 road (no buildings, as the judge's
    scene) with the point's actors at its first state; fastest wall / least CPU of 5 repeats,
    mean over the points; on 1 thread (its CPU) and in 2 threads (process CPU of both).
It leaves out: per point the SUMO start, road and scenario building (the setup s/pt column)
and the pool's dispatch; WorldState reads, contact checks and the ScenarioEngine's steps;
actor-scene rebuilds; everything done with the hits (LiDAR returns, noise, recognition, radar
equation and detection, camera photometry), fusion, planner and metrics.

Run: .venv/bin/python benchmarks/judge.py [--points 40] [--rounds 1] [--workers 2]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from raw_cast import RawCast, raw_cast_seconds, static_mesh

from hiyari.bridge.loop.warm import WarmCache
from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.presets.scenarios import ScenarioConstants, build_scenario
from hiyari.bridge.studies.r157_judge import JudgeOptions, JudgeReport, judge, point_scenario
from hiyari.risk.cc.r157_points import R157Config, R157Point, generate_points
from hiyari.traffic.simulation import SimConfig, Simulation
from hiyari.units import G

TARGET = 4.0  # points/s on 2 workers


def mixed_points(n: int, seed: int = 1) -> list[R157Point]:
    """A seeded sample of the default ODD's points: 1 in 6 cut-out, 1 in 6 deceleration, the
    rest cut-in (points of every offset from the boundary)."""
    points = generate_points(R157Config()).points
    rng = np.random.default_rng(seed)
    k = max(1, n // 6)
    take = {"cut-out": k, "decel": k, "cut-in": n - 2 * k}
    chosen = []
    for scenario, count in take.items():
        pool = [p for p in points if p.scenario == scenario]
        chosen += [pool[i] for i in sorted(rng.choice(len(pool), count, replace=False))]
    return chosen


def timed(points: list[R157Point], options: JudgeOptions) -> tuple[JudgeReport, float, float]:
    """The report, wall seconds and CPU seconds of the workers (reaped children)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    report = judge(points, options, progress=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    if options.workers == 1:
        cpu = report.cpu_seconds
    return report, wall, cpu


def floor_costs(points: list[R157Point], options: JudgeOptions) -> tuple[float, RawCast]:
    """Bare SUMO CPU seconds per simulated second over the points' runs, and the raw cast
    seconds per simulated second of the judge's rig, mean over the points' scenes (see the
    module docstring)."""
    warm = WarmCache()
    rig = warm.rig(options.sensors)
    sumo_cpu = sumo_sim = 0.0
    casts = []
    try:
        with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
            for i, p in enumerate(points):
                cs = point_scenario(p, i, options, options.perception, options.presets[0])
                preset = build_scenario(cs, Path(tmp), roads=warm)
                net = preset.network.path
                cfg = SimConfig(
                    net=net,
                    routes=preset.routes,
                    step_length=cs.step_length,
                    seed=cs.seed,
                    generated=(net, *preset.routes),
                )
                with Simulation(cfg) as sim:
                    sim.fast_forward(preset.warmup)
                    ScenarioEngine(preset.scenario, preset.roads, cs.step_length).start(sim)
                    world = sim.step()
                    c0 = time.process_time()
                    sim.run_bare(world.time + cs.duration)
                    sumo_cpu += time.process_time() - c0
                    sumo_sim += cs.duration
                static = static_mesh(preset.network)
                casts.append(raw_cast_seconds(static, world, "ego", rig, options.sensors))
    finally:
        warm.clear()
    return sumo_cpu / sumo_sim, RawCast(*np.mean(casts, axis=0))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=40)
    ap.add_argument("--rounds", type=int, default=1, help="interleaved per-run / warm rounds")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    points = mixed_points(args.points)
    fast = JudgeOptions(perception="sensors", workers=args.workers)
    arms = {"per-run": replace(fast, warm=False, end_when_decided=False), "judge": fast}
    load0 = os.getloadavg()
    runs: dict[str, list[tuple[JudgeReport, float, float]]] = {a: [] for a in arms}
    for _ in range(args.rounds):
        for arm, options in arms.items():
            runs[arm].append(timed(points, options))
    sumo_cpu, raw = floor_costs(points, fast)
    load1 = os.getloadavg()
    n = len(points)
    print(
        f"{n} R157 points ({', '.join(f'{sum(p.scenario == s for p in points)} {s}' for s in ('cut-in', 'cut-out', 'decel'))}), "
        f"camera + radar + LiDAR, clear, {args.workers} workers, {args.rounds} round(s)"
    )
    print(
        f"load average (1, 5, 15 min) before {load0[0]:.1f} {load0[1]:.1f} {load0[2]:.1f}, "
        f"after {load1[0]:.1f} {load1[1]:.1f} {load1[2]:.1f} on {os.cpu_count()} cores"
    )
    head = (
        "path",
        "points/s",
        "wall s",
        "CPU s/pt",
        "2/CPU",
        "sim s/pt",
        "setup s/pt",
        "CPU/sim s",
    )
    print(
        f"{head[0]:9s} {head[1]:>9s} {head[2]:>8s} {head[3]:>9s} {head[4]:>7s} {head[5]:>9s} "
        f"{head[6]:>10s} {head[7]:>15s}"
    )
    rate = {}
    for arm, rs in runs.items():
        rate[arm] = statistics.median(n / wall for _, wall, _ in rs)
        cpu_pt = statistics.median(cpu / n for _, _, cpu in rs)
        rep = rs[0][0]
        sim_pt = rep.sim_seconds / n
        setup_pt = statistics.median((r.run_seconds - r.loop_seconds) / n for r, _, _ in rs)
        cpu_sim = statistics.median(r.cpu_seconds / r.sim_seconds for r, _, _ in rs)
        print(
            f"{arm:9s} {rate[arm]:9.2f} {statistics.median(w for _, w, _ in rs):8.1f} "
            f"{cpu_pt:9.2f} {2 / cpu_pt:7.2f} {sim_pt:9.2f} {setup_pt:10.3f} {cpu_sim:15.3f}"
        )
    ratio = rate["judge"] / rate["per-run"]
    print(f"judge / per-run: {ratio:.2f} x points/s (median of interleaved rounds)")
    first = runs["per-run"][0][0].rows
    same_rows = all(r.rows == first for rs in runs.values() for r, _, _ in rs)
    verdicts = {arm: [(r["id"], r["verdict"]) for r in rs[0][0].rows] for arm, rs in runs.items()}
    print(
        f"identical verdicts: {verdicts['judge'] == verdicts['per-run']}; "
        f"identical judge rows (collision, impact speed, min TTC, min gap): {same_rows}"
    )
    judge_rep = runs["judge"][0][0]
    sim_pt = judge_rep.sim_seconds / n
    cpu_sim = statistics.median(r.cpu_seconds / r.sim_seconds for r, _, _ in runs["judge"])
    manoeuvre = float(np.mean([manoeuvre_seconds(p) for p in points]))
    print(
        f"closed loop with sensors: {cpu_sim:.3f} CPU s per simulated s; the judge simulates "
        f"{sim_pt:.2f} s per point (lead-in + manoeuvre alone: {manoeuvre:.2f} s)"
    )
    for what, sims in (("as judged", sim_pt), ("lead-in + manoeuvre only", manoeuvre)):
        at_cost = args.workers / (sims * cpu_sim)
        print(
            f"at the loop's own cost (not a floor), {what}: {args.workers} / ({sims:.2f} x "
            f"{cpu_sim:.3f}) = {at_cost:.2f} points/s"
        )
    print(
        f"floor costs, CPU s per simulated s: bare SUMO (simulationStep only) {sumo_cpu:.4f}; "
        f"raw Embree cast (LiDAR 10 Hz + radar 20 Hz + camera 30 Hz rays, mean of {n} point "
        f"scenes) {raw.cpu_1:.3f} on 1 thread, {raw.cpu_2:.3f} in 2 threads (wall {raw.wall_1:.3f} "
        f"and {raw.wall_2:.3f})"
    )
    for what, sims in (("as judged", sim_pt), ("lead-in + manoeuvre only", manoeuvre)):
        for threads, cast_cpu in (("on 1 thread", raw.cpu_1), ("in 2 threads", raw.cpu_2)):
            floor = args.workers / (sims * (sumo_cpu + cast_cpu))
            print(
                f"floor, {what}, raw cast {threads}: {args.workers} / ({sims:.2f} x "
                f"({sumo_cpu:.4f} + {cast_cpu:.3f})) = {floor:.2f} points/s; measured "
                f"{rate['judge']:.2f} ({rate['judge'] / floor:.2f} of it), target {TARGET:g}"
            )
    budget = args.workers / TARGET / cpu_sim
    floor_budget = args.workers / TARGET / (sumo_cpu + raw.cpu_1)
    met = rate["judge"] >= TARGET
    print(
        f"target >= {TARGET:g} points/s on {args.workers} workers: {'met' if met else 'NOT met'} "
        f"({rate['judge']:.2f} measured); it allows {budget:.2f} simulated s per point at the "
        f"loop's cost per simulated second, {floor_budget:.2f} at the floor's (1 thread)"
    )


def manoeuvre_seconds(p: R157Point, lead_in: float = ScenarioConstants().lead_in) -> float:
    """Simulated seconds before the point's other vehicles finish moving: no judge can decide
    earlier (lead-in, then the lane change or the braking to a standstill)."""
    if p.scenario == "decel":
        return lead_in + p.ve0_mps / (p.gx_max_g * G)
    return lead_in + ScenarioConstants().lane_width / p.vy_mps


if __name__ == "__main__":
    main()
