"""``hiyari run scenario.toml``: run one concrete scenario (or a small grid) in closed loop."""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

from hiyari.atomic import atomic_path
from hiyari.bridge.cli import numbers
from hiyari.errors import HiyariError, about


def run(args: argparse.Namespace) -> int:
    # the work is imported in _run so that `hiyari --help` and the other commands start fast
    with about(args.scenario):
        return _run(args)


def _run(args: argparse.Namespace) -> int:
    from hiyari.bridge.campaign.sweep import count_runs
    from hiyari.bridge.scenario.run import RunOptions, run_concrete
    from hiyari.bridge.scenario.toml_file import load_scenario

    logical = load_scenario(args.scenario)
    n = count_runs(logical)
    if n > args.max_runs:
        raise HiyariError(
            f"{args.scenario}: {n} concrete runs exceed --max-runs {args.max_runs} "
            "(use 'hiyari sweep' for large grids)"
        )
    runs = logical.expand()
    if not runs:
        raise HiyariError(f"{args.scenario}: the parameters expand to no run")
    if args.dry_run:
        for cs in runs:
            print(cs.label())
        print(f"{len(runs)} run(s); nothing run (--dry-run)")
        return 0
    out = Path(args.out)
    record = len(runs) == 1 if args.record is None else args.record
    rows = []
    for cs in runs:
        folder = out / f"run{cs.index:04d}" if len(runs) > 1 else out
        options = RunOptions(out_dir=folder, progress=not args.quiet, record=record)
        res = run_concrete(cs, options)
        d = res.as_dict()
        rows.append({"index": cs.index, "seed": cs.seed, **cs.params, **res.row()})
        ttc = "inf" if d["min_ttc_s"] is None else f"{d['min_ttc_s']:.2f} s"
        impact = (
            f" at {d['impact_speed_kmh']:.1f} km/h with {d['collided_with']}"
            if res.collision
            else ""
        )
        print(
            f"{cs.label()}: {res.verdict()}{impact}; min TTC {ttc}; "
            f"{res.sim_seconds:.1f} s simulated in {res.wall_seconds:.2f} s  -> {folder}"
            + (f" (recorded: {folder / 'run.mcap'})" if record else "")
        )
    with atomic_path(out / "results.csv") as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    n_coll = sum(r["collision"] for r in rows)
    print(f"{len(rows)} run(s), {n_coll} collision(s); table: {out / 'results.csv'}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("run", help="run a scenario file (one concrete run or a small grid)")
    p.add_argument("scenario", help="scenario file (TOML)")
    p.add_argument("-o", "--out", default="out/run", help="output folder")
    p.add_argument(
        "--max-runs", type=numbers.count(), default=50, help="refuse larger grids (use sweep)"
    )
    p.add_argument(
        "--record",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="write run.mcap (OSI + Foxglove) per run (default: on for a single run, off for "
        "a grid)",
    )
    p.add_argument(
        "--dry-run", action="store_true", help="check the file and list its runs; run nothing"
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)
