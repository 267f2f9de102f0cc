"""Soak: memory of a 48-hour incident-study arm, sampled every simulated hour.

Runs one arm of the SCT incident study (bridge/studies/sct/study.py: the unsignalised
pedestrian intersection, 200 cars/h and 300 pedestrians/h, metrics, incident detection and, in
the SCT arm, the controller) as a single 48-hour run, and reads the process's resident memory
(RSS) at every simulated hour. Baseline, measured in the same invocation in a second worker
process: the same SUMO run stepped bare (libsumo only, nothing read), sampled the same way, so
growth that SUMO itself shows is told apart from hiyari's. Prints the samples, the least-squares
slope of RSS over simulated time after the warm-up, with and without the last sample, against
the target (< 0.5 MB per simulated hour), and the RSS once the run has returned (SUMO closed,
its trip file read: after the arm, not part of it). Linux (reads /proc/self/statm).

Run: .venv/bin/python benchmarks/soak.py [--hours 48] [--arm sct|baseline] [--warmup 6]
(about 10 minutes on an idle 2-core machine for the default; --hours 12 for a quick look)
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from hiyari.bridge.studies.pool import Crashed, PoolOptions, report_progress, run_all
from hiyari.bridge.studies.sct.study import ArmTask, StudyConfig, build_inputs, run_arm
from hiyari.traffic.simulation import SimConfig, Simulation

TARGET_MB_PER_HOUR = 0.5
_PAGE = os.sysconf("SC_PAGE_SIZE")


def rss_mb() -> float:
    """Resident memory of this process, MB."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * _PAGE / 2**20


def soak_arm(task: ArmTask) -> tuple[list[tuple[float, float]], float]:
    """(simulated hour, RSS MB) at the start and after every simulated hour of ``run_arm``
    (the last one as its simulation ends), and the RSS once it has returned."""
    samples = [(0.0, rss_mb())]
    done = 0.0

    def progress(seconds: float) -> None:
        nonlocal done
        done += seconds
        report_progress(seconds)
        while done >= 3600.0 * len(samples) - 1e-6:
            samples.append((float(len(samples)), rss_mb()))

    run_arm(task, progress)
    return samples, rss_mb()


def soak_bare(task: ArmTask) -> tuple[list[tuple[float, float]], float]:
    """The same SUMO run stepped bare, RSS after every simulated hour and once closed."""
    cfg = task.study
    sim_cfg = SimConfig(
        net=task.net,
        routes=[task.routes],
        step_length=cfg.step_length,
        seed=task.seed,
        end_time=cfg.run_seconds,
    )
    samples = [(0.0, rss_mb())]
    with Simulation(sim_cfg, detect_collisions=False) as sim:
        hours = int(round(cfg.run_seconds / 3600.0))
        for h in range(1, hours + 1):
            sim.run_bare(3600.0 * h)
            samples.append((float(h), rss_mb()))
    return samples, rss_mb()


def run(task: tuple[str, ArmTask]) -> tuple[list[tuple[float, float]], float]:
    """Pool entry: ("arm" | "bare", task)."""
    kind, arm = task
    return soak_arm(arm) if kind == "arm" else soak_bare(arm)


def slope(samples: list[tuple[float, float]], warmup_h: float) -> float:
    """Least-squares slope of RSS (MB) over simulated hours after ``warmup_h``."""
    h, mb = np.array([s for s in samples if s[0] >= warmup_h]).T
    return float(np.polyfit(h, mb, 1)[0])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=48.0, help="simulated hours of the arm")
    ap.add_argument("--arm", choices=["sct", "baseline"], default="sct")
    ap.add_argument("--warmup", type=float, default=6.0, help="hours left out of the slope")
    args = ap.parse_args()
    if args.hours < args.warmup + 4:
        ap.error("--hours must exceed --warmup by at least 4 hours")
    config = StudyConfig(days=args.hours / 24.0, runs=1, variants=("unsignalised",))
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        tasks = build_inputs(config, Path(tmp) / "inputs")
        task = next(t for t in tasks if t.arm == args.arm)
        t0 = time.perf_counter()
        results: dict[str, tuple[list[tuple[float, float]], float]] = {}
        with tqdm(total=round(args.hours * 3600), unit="sim s", desc=f"{args.arm} arm") as bar:
            jobs = [("arm", task), ("bare", task)]
            for i, result in run_all(run, jobs, PoolOptions(workers=2), bar.update):
                if isinstance(result, Crashed):
                    raise SystemExit(f"soak: the {jobs[i][0]} run crashed: {result}")
                results[jobs[i][0]] = result
        wall = time.perf_counter() - t0
    (arm, arm_after), (bare, bare_after) = results["arm"], results["bare"]
    print(
        f"\n{args.arm} arm of the SCT incident study, {args.hours:.0f} simulated hours in "
        f"{wall:.0f} s wall; RSS every simulated hour (MB)"
    )
    print(f"{'hour':>5s} {'hiyari arm':>11s} {'bare SUMO':>10s}")
    for (h, a), (_, b) in zip(arm, bare, strict=False):
        if h % 4 == 0 or h == arm[-1][0]:
            print(f"{h:5.0f} {a:11.1f} {b:10.1f}")
    print(f"after the run returned (SUMO closed, trips read): {arm_after:.1f} {bare_after:.1f}")
    print(f"\nslope after {args.warmup:.0f} h warm-up (MB per simulated hour):")
    print(f"{'':23s}{'all samples':>12s} {'without the last':>17s}")
    for name, samples in (
        (f"hiyari {args.arm} arm", arm),
        ("bare SUMO (baseline)", bare),
    ):
        print(
            f"  {name:21s}{slope(samples, args.warmup):+12.3f} "
            f"{slope(samples[:-1], args.warmup):+17.3f}"
        )
    s_arm, s_bare = slope(arm, args.warmup), slope(bare, args.warmup)
    verdict = "met" if s_arm < TARGET_MB_PER_HOUR else "NOT met"
    print(f"  hiyari above baseline {s_arm - s_bare:+12.3f}")
    print(f"target: < {TARGET_MB_PER_HOUR:g} MB per simulated hour, all samples: {verdict}")


if __name__ == "__main__":
    main()
