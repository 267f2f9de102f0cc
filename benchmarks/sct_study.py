"""Wall time of the full SCT incident study against the same SUMO runs without metrics.

Runs, in this process's pool (same number of parallel processes each time):
1. the full study (default: unsignalised variant, both arms, 2 simulated days each, in 2 runs
   of 24 h per arm) with metrics, incident detection and, in the SCT arm, the controller;
2. the same SUMO runs bare: libsumo.simulationStep in a loop, nothing read;
3. the same SUMO runs stepped through hiyari's Simulation, one WorldState per step.
Prints the study's wall time and the SCT arm's time against the bare runs as ratios.
Targets: the whole study under 10 minutes; the SCT arm <= 1.5 x the bare SUMO time.

Run: .venv/bin/python benchmarks/sct_study.py [--days 2] [--variants unsignalised]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from hiyari.bridge.campaign.sct_report import summarise
from hiyari.bridge.campaign.sct_study import StudyConfig, build_inputs, run_bare_tasks, run_study


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--days", type=float, default=StudyConfig.days, help="simulated days per arm")
    ap.add_argument("--variants", default="unsignalised", help="comma-separated variants")
    ap.add_argument("--jobs", type=int, help="parallel processes (default: CPU count)")
    args = ap.parse_args()
    config = StudyConfig(days=args.days, variants=tuple(args.variants.split(",")))
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        results, study_wall = run_study(config, Path(tmp), args.jobs, progress=True)
        tasks = build_inputs(config, Path(tmp) / "inputs")
        t0 = time.perf_counter()
        bare = run_bare_tasks(tasks, read_state=False, jobs=args.jobs)
        bare_wall = time.perf_counter() - t0
        t0 = time.perf_counter()
        read = run_bare_tasks(tasks, read_state=True, jobs=args.jobs)
        read_wall = time.perf_counter() - t0
    arm = [t.arm for t in tasks]
    study_runs = {a: sum(r.wall_seconds for r in results if r.arm == a) for a in set(arm)}
    bare_runs = {a: sum(w for w, x in zip(bare, arm, strict=True) if x == a) for a in set(arm)}
    read_runs = {a: sum(w for w, x in zip(read, arm, strict=True) if x == a) for a in set(arm)}
    days = config.days
    print(
        f"SCT incident study: {', '.join(config.variants)}, {days:g} simulated days per arm, "
        f"{config.runs} run(s) per arm, step {config.step_length:g} s"
    )
    print(f"{'':46s} {'wall s':>8s} {'x bare':>8s}")
    print(f"{'bare SUMO (libsumo.simulationStep), all runs':46s} {bare_wall:8.1f} {1.0:8.2f}")
    print(
        f"{'SUMO + WorldState per step, all runs':46s} {read_wall:8.1f} "
        f"{read_wall / bare_wall:8.2f}"
    )
    print(
        f"{'full study (metrics, incidents, controller)':46s} {study_wall:8.1f} "
        f"{study_wall / bare_wall:8.2f}"
    )
    for a in ("baseline", "sct"):
        print(
            f"  {a + ' arm, summed over its runs':44s} {study_runs[a]:8.1f} "
            f"{study_runs[a] / bare_runs[a]:8.2f}   (bare {bare_runs[a]:.1f} s, "
            f"with WorldState {read_runs[a]:.1f} s: x{study_runs[a] / read_runs[a]:.2f})"
        )
    verdict = "met" if study_wall < 600 else "MISSED"
    ratio = study_runs["sct"] / bare_runs["sct"]
    print(f"target: whole study < 600 s: {study_wall:.0f} s ({verdict})")
    print(
        f"target: SCT arm <= 1.5 x bare SUMO: x{ratio:.2f} ({'met' if ratio <= 1.5 else 'MISSED'})"
    )
    for s in summarise(config, results):
        print(f"  {s.variant} {s.arm}: {s.incidents} incidents, {s.vehicles} vehicles")


if __name__ == "__main__":
    main()
