"""``hiyari sweep scenario.toml|scenario.xosc``: every concrete run of a logical scenario (or
of an OpenSCENARIO ParameterValueDistribution), in parallel."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from hiyari.bridge.cli import numbers, status
from hiyari.bridge.cli.outputs import output_folder
from hiyari.errors import about

if TYPE_CHECKING:
    from hiyari.bridge.loop.spec import Plan


def run(args: argparse.Namespace) -> int:
    from hiyari.bridge.cli.commands.runs.run import load_plan
    from hiyari.bridge.studies.report.sweep import plot_sweep
    from hiyari.bridge.studies.sweep import SweepOptions, read_table, run_sweep

    output_folder(args.out)
    # an error about the SUMO scenario names it first, and stays as it is
    world = [args.sumocfg] if args.sumocfg else []
    with about(args.scenario, Path(args.scenario).resolve(), *world):
        plan = load_plan(args)
    if args.dry_run:  # counts every run, whatever --max-runs (a real sweep refuses them)
        return _dry_run(plan, args.max_runs)
    s = run_sweep(
        plan,
        SweepOptions(
            out_dir=Path(args.out),
            backend=args.backend,
            workers=args.workers,
            ray_address=args.ray_address,
            retry_failed=args.retry_failed,
            progress=not args.quiet,
            max_runs=args.max_runs,
            in_process=args.in_process,
        ),
    )
    rows = read_table(s.table)
    plot = plot_sweep(
        plan.name, plan.varied, [rows[i] for i in sorted(rows)],
        s.table.parent / "summary.png",
    )  # fmt: skip
    skip = f"{s.total + s.constraint} runs, {s.constraint} skipped: constraint;" * bool(
        s.constraint
    )
    print(
        f"{skip or f'{s.total} runs:'} {s.ran} ran now, {s.skipped} already done, "
        f"{s.failed} failed, {s.crashed} crashed; {s.wall_seconds:.1f} s wall"
    )
    print(f"table: {s.table}" + (f"\nplot:  {plot}" if plot else ""))
    if s.crashed:
        print(
            f"hiyari: {s.crashed} run(s) crashed (their worker process died; see the error "
            "column); run the same command again to retry them",
            file=sys.stderr,
        )
        return status.RUNS_CRASHED
    return status.OK


def _dry_run(plan: Plan, max_runs: int) -> int:
    """Count the runs and list the first ones and the skipped ones; run nothing. A count
    above ``max_runs`` is said, not refused: a dry run is how one learns the count."""
    from hiyari.bridge.loop.spec import count_text

    n = plan.count()
    if n <= max_runs:  # a larger TOML grid is not expanded just to show five labels
        runs = plan.expand()
        for run in runs[:5]:
            print(run.label())
    for skipped in plan.skipped[:SHOWN_SKIPS]:
        print(skipped.label())
    more = len(plan.skipped) - SHOWN_SKIPS
    if more > 0:
        print(f"... and {more} more skipped (a sweep lists each in results.csv)")
    over = (
        f"; more than --max-runs {max_runs:,}: a sweep would refuse them (use coarser "
        "steps, or raise --max-runs)"
        if n > max_runs
        else ""
    )
    print(f"{count_text(plan)}{' (first 5 shown)' * (5 < n <= max_runs)}{over}; "
          "nothing run (--dry-run)")  # fmt: skip
    return status.OK


#: Skipped runs listed by a dry run (a sweep's results.csv lists them all).
SHOWN_SKIPS = 20


def register(sub: argparse._SubParsersAction) -> None:
    from hiyari.bridge.cli.commands.runs.run import add_world_options, add_xosc_options

    p = sub.add_parser("sweep", help="run every concrete scenario of a logical scenario file")
    p.add_argument(
        "scenario",
        help="scenario file: TOML with parameter ranges, or OpenSCENARIO .xosc (a "
        "ParameterValueDistribution, or a scenario: one run)",
    )
    add_world_options(p)
    p.add_argument("-o", "--out", default="out/sweep", help="output folder (resumable)")
    p.add_argument(
        "--workers",
        "-j",
        type=numbers.count(1, 4096),
        default=os.cpu_count() or 1,
        help="local worker processes (default: all cores)",
    )
    p.add_argument("--backend", choices=["local", "ray"], default="local")
    p.add_argument(
        "--ray-address",
        default=None,
        help="Ray cluster: 'auto' or host:port (default: start a local Ray)",
    )
    p.add_argument(
        "--max-runs",
        type=numbers.count(),
        default=10_000,
        help="refuse sweeps whose ranges give more runs than this (default: 10000)",
    )
    p.add_argument(
        "--dry-run", action="store_true", help="check the file and count its runs; run nothing"
    )
    p.add_argument("--retry-failed", action="store_true", help="run failed rows again")
    p.add_argument(
        "--in-process",
        action="store_true",
        help="run the runs one after the other in this process, not in worker processes "
        "(a native crash then ends the sweep)",
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    add_xosc_options(p)
    p.set_defaults(func=run)
