"""SCT arm of the incident study against bare SUMO stepping of the same demand.

One run of the unsignalised zebra-crossing variant (200 cars/h, 300 pedestrians/h, 0.1 s
steps, seed 1), ``--hours`` simulated hours, measured ``--repeats`` times in this process,
interleaved so that load changes hit both sides alike:

1. bare SUMO: libsumo.simulationStep in a loop, nothing read (the baseline);
2. SUMO stepped through hiyari's Simulation with a full WorldState read every step (what
   reading alone costs);
3. the SCT arm's reads and skips alone: run_arm with the per-step evaluation (metrics,
   incidents, controller) replaced by nothing, so SUMO is stepped, read and skipped as the
   study does, but nobody is commanded (SUMO's drivers throughout): the floor that faster
   metrics and control cannot go below;
4. the SCT arm (hiyari.bridge.studies.sct.study.run_arm): zone and pair bounds, metrics,
   incident detection and the SCT controller on every vehicle.

A short SCT arm (two simulated minutes) runs first and is not timed: it loads every compiled
kernel from numba's cache (or compiles it), which would otherwise land in the first timed run.

Prints the median wall and CPU times (this process's CPU time over the same span: on a
shared machine the wall time also counts waiting for a core, the CPU time does not), their
ratios to bare SUMO, the CPU time per evaluated step above bare SUMO (reads and skips) and
above the floor (the evaluation), the target (SCT arm <= 3 x bare SUMO, judged on the wall
time) and the load average. ``--profile`` adds a cProfile of one SCT arm run (top functions).

``--study-days D`` measures the whole study instead (issue 31: ``hiyari study sct --days 2 -j 2``
in under 10 minutes wall on an idle 2-core machine): both arms, D simulated days each, on
``--jobs`` worker processes as the command runs them, then bare SUMO stepping of every run of
the study in this process. Prints the study's wall time against the target, each arm's CPU
time (summed over its runs, measured in the workers) and its ratio to bare SUMO of the same
runs, and the wall time an idle machine would need (the busiest worker's CPU time: a worker
waits for nothing but its core).

Run: .venv/bin/python benchmarks/sct_study.py [--hours 1] [--repeats 3] [--profile]
     .venv/bin/python benchmarks/sct_study.py --study-days 2 [--jobs 2]
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import statistics
import tempfile
import time
from pathlib import Path

from hiyari.bridge.studies.sct import study as sct_study
from hiyari.bridge.studies.sct.study import StudyConfig, build_inputs, run_arm, run_bare

TARGET = 3.0
STUDY_TARGET_S = 600.0  # issue 31: the seed-size study in under 10 minutes wall


def _whole_study(days: float, jobs: int, seed: int) -> None:
    """The whole study as ``hiyari study sct --days D -j N`` runs it, against bare SUMO."""
    config = StudyConfig(days=days, seed=seed)
    load0 = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        results, wall = sct_study.run_study(config, tmp, jobs=jobs)
        tasks = build_inputs(config, Path(tmp) / "inputs")
        bare = {(t.arm, t.run): run_bare(t)[1] for t in tasks}
    load1 = os.getloadavg()
    print(
        f"whole SCT study: {days:g} simulated days per arm, {config.runs} runs per arm, "
        f"{jobs} workers, seed {seed}"
    )
    print(f"load average (1 min) {load0[0]:.1f} at start, {load1[0]:.1f} at end")
    print(
        f"{'arm':10s} {'runs':>5s} {'CPU s':>9s} {'bare CPU s':>11s} {'x bare':>8s} {'incidents':>10s}"
    )
    for arm in sct_study.ARMS:
        mine = [r for r in results if r.arm == arm]
        cpu = sum(r.cpu_seconds for r in mine)
        base = sum(bare[(arm, r.run)] for r in mine)
        incidents = sum(len(r.incidents) for r in mine)
        print(f"{arm:10s} {len(mine):5d} {cpu:9.1f} {base:11.1f} {cpu / base:8.2f} {incidents:10d}")
    # runs go to workers longest first (run_tasks): greedy assignment is what the pool does
    loads = [0.0] * jobs
    for r in sorted(results, key=lambda r: -r.cpu_seconds):
        loads[loads.index(min(loads))] += r.cpu_seconds
    verdict = "met" if wall < STUDY_TARGET_S else "NOT met"
    print(
        f"study wall {wall:.0f} s (target < {STUDY_TARGET_S:.0f} s: {verdict} at this load); "
        f"busiest worker's CPU {max(loads):.0f} s (about the wall time on an idle machine)"
    )


def _reads_and_skips(task: sct_study.ArmTask) -> sct_study.ArmResult:
    """run_arm with nothing evaluated on its evaluated steps (the benchmark's floor row):
    the module's evaluation is swapped out for this one call only."""
    evaluate = sct_study._evaluate
    sct_study._evaluate = lambda *args: None
    try:
        return run_arm(task)
    finally:
        sct_study._evaluate = evaluate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=1.0, help="simulated hours per run")
    ap.add_argument("--repeats", type=int, default=3, help="interleaved repetitions")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--profile", action="store_true", help="cProfile one SCT arm run")
    ap.add_argument(
        "--study-days",
        type=float,
        default=0.0,
        help="measure the whole study (both arms, D days each) instead",
    )
    ap.add_argument("--jobs", type=int, default=2, help="worker processes for --study-days")
    args = ap.parse_args()
    if args.study_days > 0:
        _whole_study(args.study_days, args.jobs, args.seed)
        return
    config = StudyConfig(days=args.hours / 24.0, runs=1, seed=args.seed)
    load0 = os.getloadavg()
    times: dict[str, list[tuple[float, float]]] = {"bare": [], "read": [], "floor": [], "sct": []}
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        warm = StudyConfig(days=120 / 86400, runs=1, seed=args.seed)
        run_arm(next(t for t in build_inputs(warm, Path(tmp) / "warm") if t.arm == "sct"))
        task = next(t for t in build_inputs(config, Path(tmp)) if t.arm == "sct")
        for _ in range(args.repeats):
            times["bare"].append(run_bare(task))
            times["read"].append(run_bare(task, read_state=True))
            floor = _reads_and_skips(task)
            times["floor"].append((floor.wall_seconds, floor.cpu_seconds))
            result = run_arm(task)
            times["sct"].append((result.wall_seconds, result.cpu_seconds))
        if args.profile:
            prof = cProfile.Profile()
            prof.runcall(run_arm, task)
    wall = {k: statistics.median(w for w, _ in v) for k, v in times.items()}
    cpu = {k: statistics.median(c for _, c in v) for k, v in times.items()}
    load1 = os.getloadavg()
    print(
        f"SCT arm vs bare SUMO: unsignalised zebra crossings, {args.hours:g} simulated h, "
        f"step {config.step_length:g} s, seed {args.seed}, median of {args.repeats} "
        f"interleaved runs"
    )
    print(f"load average (1 min) {load0[0]:.1f} at start, {load1[0]:.1f} at end")
    print(f"{'':44s} {'wall s':>8s} {'x bare':>8s} {'CPU s':>8s} {'x bare':>8s}")
    rows = [
        ("bare SUMO (libsumo.simulationStep)", "bare"),
        ("SUMO + WorldState read every step", "read"),
        ("SCT arm's reads and skips, no evaluation", "floor"),
        ("SCT arm (metrics, incidents, controller)", "sct"),
    ]
    for label, key in rows:
        print(
            f"{label:44s} {wall[key]:8.2f} {wall[key] / wall['bare']:8.2f} "
            f"{cpu[key]:8.2f} {cpu[key] / cpu['bare']:8.2f}"
        )
    steps = result.steps
    print(
        f"SCT arm: {result.evaluated_steps} of {steps} steps evaluated "
        f"({100 * result.evaluated_steps / steps:.0f} %), {result.interventions} commands, "
        f"{len(result.encounters)} encounters, {len(result.incidents)} incidents"
    )
    print(
        f"reads and skips alone: {floor.evaluated_steps} steps read for evaluation "
        f"(SUMO's drivers, so a little different from the SCT arm's)"
    )
    per_floor = 1e6 * (cpu["floor"] - cpu["bare"]) / floor.evaluated_steps
    per_eval = 1e6 * (cpu["sct"] - cpu["floor"]) / result.evaluated_steps
    print(
        f"CPU per evaluated step: reads and skips {per_floor:.0f} us above bare SUMO, "
        f"evaluation {per_eval:.0f} us above the reads and skips"
    )
    ratio = wall["sct"] / wall["bare"]
    verdict = "met" if ratio <= TARGET else "NOT met"
    print(
        f"target: SCT arm <= {TARGET:g} x bare SUMO: x{ratio:.1f} wall, "
        f"x{cpu['sct'] / cpu['bare']:.1f} CPU ({verdict})"
    )
    if args.profile:
        pstats.Stats(prof).sort_stats("tottime").print_stats(25)


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"benchmark wall time {time.perf_counter() - started:.0f} s")
