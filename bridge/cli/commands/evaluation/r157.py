"""``hiyari r157 ...``: UN R157 (JAMA Annex G) test points and their evaluation.

A command group: each subcommand is one ``add_<name>(subparsers)`` function in
``SUBCOMMANDS`` that adds its parser and sets ``func``.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections import Counter
from typing import TYPE_CHECKING

from hiyari.bridge.cli import status
from hiyari.bridge.cli.commands.evaluation.boundary import add_model_options, model_params
from hiyari.bridge.cli.outputs import output_folder
from hiyari.errors import HiyariError
from hiyari.risk.cc.boundary import Grid
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.r157_points import (
    SCENARIOS,
    R157Config,
    generate_points,
    write_points_csv,
    write_points_json,
)

if TYPE_CHECKING:
    from hiyari.bridge.studies.r157_judge import JudgeReport


def run_points(args: argparse.Namespace) -> int:
    out = output_folder(args.out)
    scenarios = tuple(s.strip() for s in args.scenarios.split(",") if s.strip())
    if args.resolution <= 0:
        raise HiyariError(f"--resolution must be > 0 m, got {args.resolution}")
    config = R157Config(
        ve0_kmh=Grid.parse(args.ve, "--ve"),
        dv_kmh=Grid.parse(args.dv, "--dv"),
        vy_fine=Grid.parse(args.vy_fine, "--vy-fine"),
        vy_coarse=Grid.parse(args.vy_coarse, "--vy-coarse"),
        gx_max_g=Grid.parse(args.gx, "--gx"),
        scenarios=scenarios,
        resolution_m=args.resolution,
    )
    point_set = generate_points(config, model_params(args))
    csv_path = write_points_csv(point_set.points, out / "r157_points.csv")
    json_path = write_points_json(point_set, out / "r157_points.json")
    print(f"{len(point_set.points)} R157 test points ({point_set.params.convention_note()}):")
    for key, count in sorted(point_set.counts().items()):
        print(f"   {key}: {count}")
    for reason, count in sorted(point_set.skipped.items()):
        print(f"   skipped, {reason}: {count}")
    print(f"   {csv_path}\n   {json_path}")
    return 0


def add_points(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "points",
        help="test points on / around the C&C Preventable boundaries (Annex G.5.7)",
        description="Concrete scenarios with their expected verdict, as CSV and JSON.",
    )
    p.add_argument("-o", "--out", default="out/r157", help="output folder")
    p.add_argument("--ve", default="20:60:10", help="ODD ego speeds Ve0, km/h start:stop:step")
    p.add_argument("--dv", default="0:60:10", help="cut-in relative speeds Ve0 - Vo0, km/h")
    p.add_argument("--vy-fine", default="0.1:3:0.1", help="Vy for boundary, +1, +2 m (m/s)")
    p.add_argument("--vy-coarse", default="0.5:3:0.5", help="Vy for +10, +30, -5 m (m/s)")
    p.add_argument("--gx", default="0.1:1:0.1", help="deceleration-scenario Gx_max, g")
    p.add_argument(
        "--scenarios", default=",".join(SCENARIOS), help="comma list of cut-in,cut-out,decel"
    )
    p.add_argument("--resolution", type=float, default=0.1, help="boundary rounding, m")
    add_model_options(p)
    p.set_defaults(func=run_points)


def run_judge(args: argparse.Namespace) -> int:
    from hiyari.bridge.studies.r157_judge import JudgeOptions, judge
    from hiyari.bridge.studies.report.r157 import write_report
    from hiyari.risk.cc.r157_points import load_point_params, load_points

    for option, given in (("--sumocfg", args.sumocfg), ("--map", args.map)):
        if given:
            raise HiyariError(
                f"{option}: an R157 test point is its Annex G manoeuvre alone on a straight "
                "expressway, its expected verdict computed for exactly that; other traffic "
                "would judge another scenario (run a .xosc in a SUMO scenario with 'hiyari run "
                "x.xosc --sumocfg' instead)"
            )
    out = output_folder(args.out)
    points = load_points(args.points)
    stored, given = load_point_params(args.points), model_params(args)
    if stored is not None and given != CCParams() and given != stored:
        raise HiyariError(
            f"{args.points}: its points were made with another C&C model "
            f"({stored.convention_note()}, aeb={stored.aeb}) than the model options given: "
            "drop the options (the file's model is used) or regenerate the points"
        )
    params = stored or given
    if args.scenarios:
        wanted = {s.strip() for s in args.scenarios.split(",")}
        points = [p for p in points if p.scenario in wanted]
    if not points:
        raise HiyariError(f"{args.points}: no test points to run")
    if args.sample is not None and args.sample < 1:
        raise HiyariError(f"--sample must be >= 1, got {args.sample}")
    options = JudgeOptions(
        perception=args.perception,
        presets=tuple(p.strip() for p in args.presets.split(",") if p.strip()),
        aeb_delay=args.aeb_delay,
        workers=args.workers,
        in_process=args.in_process,
        sample=args.sample,
        seed=args.seed,
        params=params,
    )
    report = judge(points, options, progress=not args.quiet)
    paths = write_report(report, out)
    for cond, s in report.summary().items():
        print(
            f"{cond}: {s['verdict'].upper()}: {s['passed']}/{s['preventable']} Preventable points "
            f"passed, {s['failed']} failed, {s['preventable_not_tested']} not tested; "
            f"{s['unpreventable_collided']} of {s['points'] - s['preventable']} unpreventable "
            f"points collided; {s['tested']} of {s['points']} points tested, "
            f"{s['not_tested']} not tested; {s['near_misses']} near misses, "
            f"{s['false_activations']} false activations"
        )
        for pid in s["not_tested_points"][:10]:
            print(f"   not tested: {pid}")
        for pid in s["failed_points"][:10]:
            print(f"   failed: {pid}")
        if s["failed"] > 10:
            print(f"   ... and {s['failed'] - 10} more (see judge.csv)")
        if s["crashed"]:
            print(f"   {s['crashed']} point(s) crashed (worker process died; see judge.csv)")
    _print_differences(report)
    for p in paths:
        print(f"   {p}")
    summary = report.summary().values()
    crashed = sum(s["crashed"] for s in summary)
    if crashed:
        print(
            f"hiyari: {crashed} run(s) crashed (their worker process died); run the same "
            "command again to judge them",
            file=sys.stderr,
        )
    return status.verdict(all(s["verdict"] == "pass" for s in summary), crashed)


def _print_differences(report: JudgeReport) -> None:
    """Per condition other than perfect perception: verdicts equal to perfect perception's, and
    the differences by cause."""
    from hiyari.bridge.studies.r157_compare import PERFECT, differences, rig_reach_m

    if PERFECT not in report.conditions:
        return
    diffs = differences(report.rows, rig_reach_m())
    n_points = sum(r["condition"] == PERFECT for r in report.rows)
    for cond in report.conditions:
        if cond == PERFECT:
            continue
        mine = [d for d in diffs if d.condition == cond]
        causes = Counter(d.cause for d in mine)
        by = ", ".join(f"{n} {c}" for c, n in causes.most_common())
        print(
            f"{cond} against perfect perception: {n_points - len(mine)} of {n_points} verdicts "
            f"equal" + (f"; {len(mine)} differ: {by} (differences.csv)" if mine else "")
        )


def add_judge(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "judge",
        help="run test points through the closed loop and judge pass / fail",
        description="Every Preventable point must be passed without a collision (exit status "
        "3 when a condition fails, 4 when a run crashed). The points' "
        "expected verdicts are checked against the C&C model: the one stored in a JSON points "
        "file (model options that differ from it are refused), else the model options given "
        "here.",
    )
    p.add_argument("points", help="points file from 'hiyari r157 points' (CSV or JSON)")
    p.add_argument("-o", "--out", default="out/r157_judge", help="output folder")
    p.add_argument(
        "--perception",
        default="perfect",
        help="perfect, sensors or none, or a comma list: each is a condition (perfect,sensors "
        "lists every point whose verdict differs from perfect perception's, with the "
        "perception limit that explains it, in differences.csv)",
    )
    p.add_argument(
        "--presets",
        default="clear",
        help="disturbance presets for --perception sensors, comma list",
    )
    p.add_argument("--scenarios", default="", help="only these scenario types (comma list)")
    p.add_argument("--sample", type=int, default=None, help="a seeded random subset of N points")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--aeb-delay", type=float, default=0.2, help="brake actuation delay, s")
    p.add_argument("--workers", "-j", type=int, default=os.cpu_count() or 1)
    p.add_argument(
        "--in-process",
        action="store_true",
        help="run the points one after the other in this process, not in worker processes "
        "(a native crash then ends the judge)",
    )
    world = p.add_mutually_exclusive_group()
    for option in ("--sumocfg", "--map"):  # accepted so that the refusal says why
        world.add_argument(
            option, help="refused: the points run alone on the Annex G expressway (docs)"
        )
    p.add_argument("-q", "--quiet", action="store_true")
    add_model_options(p)
    p.set_defaults(func=run_judge)


# Each adds one ``hiyari r157 <name>`` subcommand.
SUBCOMMANDS = [add_points, add_judge]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("r157", help="UN R157 test points (JAMA Annex G)")
    commands = p.add_subparsers(dest="r157_command", required=True, metavar="SUBCOMMAND")
    for add in SUBCOMMANDS:
        add(commands)
