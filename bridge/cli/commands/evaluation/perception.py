"""``hiyari perception``: JAMA perception and vehicle-motion disturbances (coverage, sweeps,
grip use, blind spots)."""

from __future__ import annotations

import argparse
import sys

from hiyari.bridge.cli import numbers, status
from hiyari.bridge.cli.outputs import output_folder


def _coverage(args: argparse.Namespace) -> int:
    from hiyari.bridge.studies.perception.coverage_run import parse_sensors, write_coverage

    text, paths = write_coverage(parse_sensors(args.sensors), output_folder(args.out))
    print(text)
    for p in paths.values():
        print(f"written: {p}")
    return 0


def _sweep(args: argparse.Namespace) -> int:
    from hiyari.bridge.studies.perception.sweep import SweepConfig
    from hiyari.bridge.studies.perception.sweep_run import run_sweep

    cfg = SweepConfig(levels=args.levels, frames=args.frames, seed=args.seed)
    rows, paths = run_sweep(args.disturbances, cfg, output_folder(args.out))
    print(paths["md"].read_text())
    for p in paths.values():
        print(f"written: {p}")
    return 0


def _grip(args: argparse.Namespace) -> int:
    from hiyari.bridge.studies.grip.study import GripStudy, run_study
    from hiyari.bridge.studies.report.grip import write_grip_report

    out = output_folder(args.out)
    study = GripStudy()
    paths = write_grip_report(run_study(study, progress=True), study, out)
    print(paths["md"].read_text())
    for p in paths.values():
        print(f"written: {p}")
    return 0


def _blindspots(args: argparse.Namespace) -> int:
    from hiyari.bridge.studies.perception.blindspot.run import run_catalogue
    from hiyari.bridge.studies.pool import PoolOptions
    from hiyari.bridge.studies.report.blindspot import write_catalogue

    out = output_folder(args.out)
    pool = PoolOptions(in_process=args.in_process)
    results = run_catalogue(out / "blindspot_roads", not args.no_run, args.cases or None, pool=pool)
    paths = write_catalogue(results, out)
    print(paths["md"].read_text())
    for p in paths.values():
        print(f"written: {p}")
    crashed = sum(bool(r.crashed) for r in results)
    if crashed:
        print(
            f"hiyari: {crashed} closed-loop run(s) crashed (their worker process died); run the "
            "same command again",
            file=sys.stderr,
        )
        return status.RUNS_CRASHED
    return status.OK


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "perception",
        help="JAMA perception / vehicle-motion disturbances: coverage, sweep, grip, blind spots",
    )
    psub = p.add_subparsers(dest="perception_command", required=True, metavar="SUBCOMMAND")
    c = psub.add_parser(
        "coverage",
        help="which JAMA principles each simulated disturbance exercises, per sensor and merged",
    )
    c.add_argument("--sensors", default="camera,radar,lidar", help="comma-separated sensors")
    c.add_argument("-o", "--out", default="out/perception", help="output folder")
    c.set_defaults(func=_coverage)
    w = psub.add_parser(
        "sweep",
        help="sweep the representative disturbances over their range for the standard targets",
    )
    w.add_argument(
        "--disturbances", nargs="*", help="disturbance names (default: the representative set)"
    )
    w.add_argument("--levels", type=numbers.count(lo=2), default=3, help="intensities each")
    w.add_argument("--frames", type=numbers.count(lo=2), default=2, help="frames per distance")
    w.add_argument("--seed", type=numbers.seed(), default=7)
    w.add_argument("-o", "--out", default="out/perception", help="output folder")
    w.set_defaults(func=_sweep)
    g = psub.add_parser(
        "grip",
        help="vehicle-motion disturbances: grip use through the expressway curve per mu and speed",
    )
    g.add_argument("-o", "--out", default="out/perception", help="output folder")
    g.set_defaults(func=_grip)
    b = psub.add_parser(
        "blindspots",
        help="JAMA blind-spot catalogue: ray-cast occlusion check and closed-loop run per case",
    )
    b.add_argument("--cases", nargs="*", help="case names (default: every realisable one)")
    b.add_argument("--no-run", action="store_true", help="occlusion check only, no closed loop")
    b.add_argument(
        "--in-process",
        action="store_true",
        help="closed-loop runs one after the other in this process, not in worker processes "
        "(a native crash then ends the command)",
    )
    b.add_argument("-o", "--out", default="out/perception", help="output folder")
    b.set_defaults(func=_blindspots)
