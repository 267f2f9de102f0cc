"""``hiyari study sct``: the pedestrian incident study, SUMO's drivers against SCT drivers."""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from typing import TYPE_CHECKING

from hiyari.bridge.cli import numbers, status
from hiyari.bridge.cli.outputs import output_folder
from hiyari.errors import HiyariError

if TYPE_CHECKING:
    from hiyari.bridge.studies.sct.study import StudyConfig


def study_config(args: argparse.Namespace) -> StudyConfig:
    """The StudyConfig the command line asks for (validated)."""
    # the study loads SUMO and the SCT model: imported when it runs, not for `hiyari --help`
    from hiyari.bridge.loop.drivers.sct_controller import SCTControllerConfig
    from hiyari.bridge.studies.sct.study import VARIANTS, WORLD_VARIANT, StudyConfig
    from hiyari.risk.metrics.incidents import IncidentConfig

    base = StudyConfig()
    world = args.map or args.sumocfg
    _refuse_without_meaning(args, world)
    variants = tuple(v.strip() for v in (args.variants or "").split(",") if v.strip())
    if args.variants == "both":
        variants = tuple(VARIANTS)
    if world:
        variants = (WORLD_VARIANT,)
    crossings = ()
    if args.crossings is not None and args.crossings.strip() != "auto":
        crossings = tuple(c.strip() for c in args.crossings.split(",") if c.strip())
        if not crossings:
            raise HiyariError("--crossings: give 'auto' or crossing ids such as :J_c0")
    days = base.days if args.days is None else args.days
    if args.sumocfg and args.days is None:  # each run the scenario's whole time window
        days = _window_days(args.sumocfg, args.runs) or days
    config = StudyConfig(
        days=days,
        vehicles_per_hour=base.vehicles_per_hour if args.vph is None else args.vph,
        persons_per_hour=args.pph,
        variants=variants or base.variants,
        crossing_priority=not args.minor_crossings,
        runs=args.runs,
        seed=args.seed,
        penetration=args.penetration,
        controller=replace(SCTControllerConfig(), sct_safe=args.sct_safe),
        incidents=replace(
            IncidentConfig(), ttc_threshold=args.ttc_threshold, pet_threshold=args.pet_threshold
        ),
        sct=base.sct,
        map_net=args.map or "",
        sumocfg=args.sumocfg or "",
        crossings=crossings,
    )
    config.validate()
    return config


def _refuse_without_meaning(args: argparse.Namespace, world: str | None) -> None:
    """One line for an option that means nothing with (or without) a map or scenario."""
    if world:
        given = {"--variants": args.variants is not None,
                 "--minor-crossings": args.minor_crossings, "--sensitivity": args.sensitivity > 0}  # fmt: skip
        used = [option for option, on in given.items() if on]
        if used:
            raise HiyariError(f"{used[0]}: applies to the generated intersection; on a map "
                              "the junctions are the map's, as they are")  # fmt: skip
    elif args.crossings is not None:
        raise HiyariError("--crossings: choose crossings on a map (--map or --sumocfg)")
    if args.sumocfg and args.vph is not None:
        raise HiyariError("--vph: in a SUMO scenario its own vehicles are the study's")


def _window_days(sumocfg: str, runs: int) -> float | None:
    """Days of ``runs`` runs each as long as the SUMO scenario's time window (None: it has
    no end, which the study refuses)."""
    from hiyari.traffic.sumocfg import read_sumocfg

    sc = read_sumocfg(sumocfg)
    return None if sc.end is None else runs * (sc.end - sc.begin) / 86400.0


def run_sct(args: argparse.Namespace) -> int:
    from hiyari.bridge.studies.report.sct import write_report
    from hiyari.bridge.studies.sct.study import run_study, study_world
    from hiyari.bridge.studies.sct.summary import SEED_REDUCTION, change_text, reduction, summarise

    config = study_config(args)
    if args.jobs is not None and args.jobs < 1:
        raise HiyariError(f"--jobs must be >= 1, got {args.jobs}")
    study_world(config)  # a bad map, scenario or crossing id is refused before any output
    out = output_folder(args.out)
    results, wall = run_study(
        config, out, args.jobs, progress=not args.quiet, in_process=args.in_process
    )
    sensitivity = None
    if args.sensitivity:
        from hiyari.bridge.studies.sct.sensitivity import run_sensitivity

        sensitivity = (
            args.sensitivity,
            run_sensitivity(config, out, args.sensitivity, jobs=args.jobs),
        )
    report = write_report(out, config, results, wall, sensitivity)
    for s in summarise(config, results):
        print(
            f"{s.variant:13s} {s.arm:9s} incidents {s.incidents:5d} (collisions {s.collisions}), "
            f"mean travel time {s.mean_travel_time:6.1f} s, delay {s.mean_time_loss:5.1f} s"
        )
    by = {(s.variant, s.arm): s for s in summarise(config, results)}
    for v in config.variants:
        base, sct = by[(v, "baseline")], by[(v, "sct")]
        red = reduction(base.incidents, sct.incidents)
        cost = sct.mean_travel_time - base.mean_travel_time
        print(
            f"{v}: {base.incidents} -> {sct.incidents} incidents ({change_text(red)}; seed "
            f"{-SEED_REDUCTION:+.0%}), travel time {cost:+.1f} s per vehicle"
        )
    print(f"study wall time {wall:.0f} s; report: {report}")
    print(f"outputs in {out.resolve()}: report.md, summary.json, incidents.csv, *.png, inputs/")
    crashed = [r for r in results if r.crashed]
    if crashed:
        print(
            f"hiyari: {len(crashed)} run(s) crashed and are left out of the report (e.g. "
            f"{crashed[0].variant} {crashed[0].arm} seed {crashed[0].seed}: "
            f"{crashed[0].crashed}); run the same command again",
            file=sys.stderr,
        )
        return status.RUNS_CRASHED
    return status.OK


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("study", help="incident studies over long SUMO runs")
    studies = p.add_subparsers(dest="study", required=True, metavar="STUDY")
    studies.add_parser(
        "sct",
        help="SUMO drivers vs Safety Cushion Time drivers at a pedestrian intersection",
        description="Runs the baseline arm (SUMO's drivers) and the SCT arm with the same "
        "demand and seeds, in parallel processes, and writes a report (Markdown, PNG, CSV).",
        setup=_sct_arguments,  # the defaults come from the study's configuration
    )


def _sct_arguments(s: argparse.ArgumentParser) -> None:
    from hiyari.bridge.studies.sct.study import StudyConfig

    d = StudyConfig()
    s.add_argument("--out", "-o", default="out/study_sct", help="report folder")
    world = s.add_mutually_exclusive_group()
    world.add_argument(
        "--map",
        help="study on this SUMO net (e.g. from 'hiyari net import map.osm') with generated "
        "vehicles, instead of the generated intersection",
    )
    world.add_argument(
        "--sumocfg",
        help="study inside this SUMO scenario: its own vehicles and persons over its time "
        "window, plus the study's pedestrians at the crossings",
    )
    s.add_argument(
        "--crossings",
        default=None,
        help="with --map / --sumocfg: 'auto' (default: every crossing of the net with a "
        "sidewalk at both ends) or comma-separated crossing ids (:J_c0) the study's "
        "pedestrians walk across",
    )
    s.add_argument(
        "--days",
        type=numbers.number(None, 3660, unit="days"),  # > 0 checked by the study config
        default=None,
        help=f"simulated days per arm (default: {d.days}); with --sumocfg, each run is the "
        "scenario's time window unless given",
    )
    s.add_argument(
        "--vph",
        type=numbers.per_hour(),
        default=None,
        help=f"vehicles per hour (default: {d.vehicles_per_hour}); not with --sumocfg",
    )
    s.add_argument(
        "--pph",
        type=numbers.per_hour(),
        default=d.persons_per_hour,
        help="pedestrians per hour (on a map: walking across the chosen crossings)",
    )
    s.add_argument(
        "--variants",
        default=None,
        help="comma-separated intersection variants: unsignalised, signalised (or 'both'; "
        f"default: {','.join(d.variants)})",
    )
    s.add_argument(
        "--minor-crossings",
        action="store_true",
        help="unsignalised crossings without priority (netconvert's default: pedestrians wait "
        "for gaps) instead of zebra crossings where drivers yield",
    )
    s.add_argument(
        "--runs",
        type=numbers.count(1, 100_000),
        default=d.runs,
        help="independent runs (seeds) per arm",
    )
    s.add_argument("--seed", type=numbers.seed(), default=d.seed, help="seed of the first run")
    s.add_argument(
        "--penetration",
        type=numbers.number(),  # range checked by the study config
        default=d.penetration,
        help="share of SCT vehicles in the SCT arm (0..1)",
    )
    s.add_argument(
        "--sct-safe",
        type=numbers.number(0, 60, lo_open=True, unit="s"),
        default=d.controller.sct_safe,
        help="SCT_safe, s",
    )
    s.add_argument(
        "--ttc-threshold",
        type=numbers.number(0, 60, lo_open=True, unit="s"),
        default=d.incidents.ttc_threshold,
        help="incident TTC, s",
    )
    s.add_argument(
        "--pet-threshold",
        type=numbers.number(None, 60, unit="s"),  # > 0 checked by the incident config
        default=d.incidents.pet_threshold,
        help="incident PET, s",
    )
    s.add_argument(
        "--jobs", "-j", type=numbers.count(1, 4096), help="parallel processes (default: CPU count)"
    )
    s.add_argument(
        "--in-process",
        action="store_true",
        help="run the runs one after the other in this process, not in worker processes "
        "(a native crash then ends the study)",
    )
    s.add_argument(
        "--sensitivity",
        type=numbers.number(0, 24 * 3660, unit="h"),
        default=0.0,
        metavar="HOURS",
        help="also run the sensitivity points (SCT_safe, penetration, pedestrian demand), "
        "HOURS simulated hours per arm and point (0: none)",
    )
    s.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    s.set_defaults(func=run_sct)
