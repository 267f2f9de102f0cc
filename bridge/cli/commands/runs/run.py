"""``hiyari run scenario.toml|scenario.xosc``: run one concrete scenario (or a small grid, or
the runs of an OpenSCENARIO parameter distribution) in closed loop."""

from __future__ import annotations

import argparse
import csv
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from hiyari.atomic import atomic_path
from hiyari.bridge.cli import numbers, status
from hiyari.bridge.cli.outputs import output_folder
from hiyari.errors import HiyariError, about

if TYPE_CHECKING:
    from hiyari.bridge.loop.result import RunResult
    from hiyari.bridge.loop.spec import EgoSetup, Plan, PlannedRun
    from hiyari.bridge.openscenario.presets.scenarios import World


def run(args: argparse.Namespace) -> int:
    output_folder(args.out)
    # the work is imported below so that `hiyari --help` and the other commands start fast
    if args.scenario is None and args.sumocfg is None and args.map is None:
        args.run_parser.error(
            "the following arguments are required: scenario (or a world: --sumocfg, --map)"
        )
    if args.scenario is None:
        return _run(args, load_plan(args))
    # an error about the SUMO scenario names it first, and stays as it is
    world = [args.sumocfg] if args.sumocfg else []
    with about(args.scenario, Path(args.scenario).resolve(), *world):
        return _run(args, load_plan(args))


def load_plan(args: argparse.Namespace) -> Plan:
    """The runs of the scenario file the command line names (the one place the file's type
    is decided, by its extension), with the command line's options over the file's."""
    from hiyari.bridge.loop.toml_runs import TomlPlan
    from hiyari.bridge.loop.xosc_runs import is_openscenario
    from hiyari.bridge.loop.xosc_runs import load_plan as load_xosc
    from hiyari.bridge.openscenario.presets.toml_file import load_scenario, parse_scenario

    world_given = getattr(args, "sumocfg", None) or getattr(args, "map", None)
    warmup = getattr(args, "warmup", None)
    if args.scenario is not None and is_openscenario(args.scenario):
        if getattr(args, "map", None):
            raise HiyariError(f"{args.scenario}: an OpenSCENARIO file runs on the road its "
                              "LogicFile names (--map applies to city scenarios)")  # fmt: skip
        if warmup is not None and not args.sumocfg:
            raise HiyariError("--warmup: the warm-up is of a SUMO scenario's demand (--sumocfg)")
        world = _world(args) if world_given else None  # --sumocfg: --map is refused above
        sumo = world.sumo if world is not None else None
        setup, params = ego_setup(args), xosc_params(args)
        ego = getattr(args, "ego", None)
        return load_xosc(args.scenario, setup, params, sumo, warmup or 0.0, ego=ego)
    if getattr(args, "ego", None) is not None:
        raise HiyariError(f"{args.scenario}: --ego names the ego of an OpenSCENARIO file")
    if warmup is not None:
        raise HiyariError("--warmup: a city scenario's warm-up is its warmup_s parameter")
    world = _world(args) if world_given else None  # named before the scenario expands
    if args.scenario is None:  # free city driving with the city defaults in that world
        logical = parse_scenario({"scenario": {"type": "city"}}, "--sumocfg/--map")
    else:
        logical = load_scenario(args.scenario)
    if xosc_params(args):
        raise HiyariError(
            f"{args.scenario}: --param sets OpenSCENARIO parameters; a TOML file's are set in "
            "its [parameters]"
        )
    return TomlPlan(logical, world, args.perception, environment(args))


def _world(args: argparse.Namespace) -> World | None:
    """The map or SUMO scenario a city run drives in (None: the generated city)."""
    from hiyari.bridge.openscenario.presets.scenarios import World

    if args.sumocfg is not None:
        return World.of_sumocfg(args.sumocfg)
    if args.map is not None:
        return World.of_net(args.map)
    return None


def ego_setup(args: argparse.Namespace) -> EgoSetup:
    """The EgoSetup the command line asks for (OpenSCENARIO runs)."""
    from hiyari.bridge.loop.spec import EgoSetup

    return EgoSetup(
        perception=args.perception or "perfect",
        environment=environment(args) or "clear",
        step_length=args.step_length,
        seed=args.seed,
        max_duration=args.max_duration,
    )


def environment(args: argparse.Namespace) -> str | None:
    """The ``--environment`` preset, checked (None: not given)."""
    from hiyari.sensors.environment.presets import disturbance_preset

    if args.environment is not None:
        try:
            disturbance_preset(args.environment)
        except HiyariError as exc:
            raise HiyariError(f"--environment: {exc}") from None
    return args.environment


def xosc_params(args: argparse.Namespace) -> dict[str, str]:
    """The ``--param NAME=VALUE`` options by name (OpenSCENARIO files only: load_plan)."""
    params: dict[str, str] = {}
    for text in args.param:
        name, eq, value = text.partition("=")
        name = name.strip()
        if not eq or not name:
            raise HiyariError(f"--param: expected NAME=VALUE, got {text!r}")
        if name in params:
            raise HiyariError(f"--param: {name} is given twice")
        params[name] = value.strip()
    return params


def _run(args: argparse.Namespace, plan: Plan) -> int:
    """Run (or with ``--dry-run`` check) every run of ``plan`` (see ``register``)."""
    import tempfile

    n = plan.count()
    if n > args.max_runs and not args.dry_run:  # a dry run counts them all
        raise HiyariError(
            f"{plan.path}: {n} runs exceed --max-runs {args.max_runs} "
            "(use 'hiyari sweep' for large grids and distributions)"
        )
    with tempfile.TemporaryDirectory(prefix="hiyari-road-") as tmp:
        # a shared road is made before anything is written: a bad road leaves no output
        runs = plan.with_roads(Path(tmp)).expand()
        if not runs:
            raise HiyariError(f"{plan.path}: the parameters expand to no run")
        if args.dry_run:
            return _dry_run(plan, runs, args.max_runs)
        return _run_each(plan, runs, args)


def _dry_run(plan: Plan, runs: Sequence[PlannedRun], limit: int) -> int:
    """Make every check each of the first ``limit`` runs makes before its first step and
    print their labels; count the rest, and list the runs skipped for their constraints.
    Nothing is run or written."""
    from hiyari.bridge.loop.execute import check
    from hiyari.bridge.loop.spec import count_text

    for run in runs[:limit]:
        with run.spec() as spec:
            check(spec)
        print(f"{run.label()}: ready")
    for skipped in plan.skipped:
        print(skipped.label())
    checked = min(len(runs), limit)
    rest = (
        f"; {len(runs) - checked} more counted, not checked (--max-runs)"
        if len(runs) > limit
        else ""
    )
    print(
        f"{count_text(plan)}; {checked} checked up to their first step{rest}; "
        "nothing run (--dry-run)"
    )
    return status.OK


def _run_each(plan: Plan, runs: Sequence[PlannedRun], args: argparse.Namespace) -> int:
    """Run every concrete run into its folder, print each verdict and write results.csv; the
    exit status (VERDICT_FAIL when the ego collided in a run)."""
    from hiyari.bridge.loop.execute import RunOptions, execute
    from hiyari.bridge.studies.report.timeseries import plot_timeseries

    out = Path(args.out)
    record = len(runs) == 1 if args.record is None else args.record
    rows = []
    for skipped in plan.skipped:  # said first: a reader sees at once which runs will not come
        print(skipped.label())
    for run in runs:
        folder = out / f"run{run.index:04d}" if len(runs) > 1 else out
        options = RunOptions(
            out_dir=folder, progress=not args.quiet, record=record, plot=plot_timeseries
        )
        try:
            with run.spec() as spec:
                res = execute(spec, options)
        except KeyboardInterrupt as exc:  # Ctrl-C or SIGTERM: say what is (not) kept
            exc.args = (_unfinished(run.label(), folder),)
            raise
        rows.append({"index": run.index, "seed": run.seed, **run.params, **res.row()})
        _print_run(run.label(), res, folder, record)
    _write_table(out, rows, len(plan.skipped))
    return status.verdict(not any(r["collision"] for r in rows))


def _unfinished(label: str, folder: Path) -> str:
    """What an interrupted ``run`` keeps, in one line."""
    part = folder / "run.mcap.part"
    kept = f"; {part} holds its recording so far" if part.is_file() else ""
    return f"{label} not finished: nothing of it is written under a final name{kept}"


def _print_run(label: str, res: RunResult, folder: Path, record: bool) -> None:
    d = res.as_dict()
    ttc = "inf" if d["min_ttc_s"] is None else f"{d['min_ttc_s']:.2f} s"
    gap = "" if d["min_gap_m"] is None else f"; min gap {d['min_gap_m']:.2f} m"
    impact = (
        f" at {d['impact_speed_kmh']:.1f} km/h with {d['collided_with']}" if res.collision else ""
    )
    print(
        f"{label}: {res.verdict()}{impact}; min TTC {ttc}{gap}; "
        f"{res.sim_seconds:.1f} s simulated in {res.wall_seconds:.2f} s  -> {folder}"
        + (f" (recorded: {folder / 'run.mcap'})" if record else "")
    )


def _write_table(out: Path, rows: list[dict], skipped: int = 0) -> None:
    columns = list(dict.fromkeys(k for r in rows for k in r))
    with atomic_path(out / "results.csv") as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        w.writerows(rows)
    n_coll = sum(r["collision"] for r in rows)
    skip = f", {skipped} skipped: constraint" if skipped else ""
    untested = sum(r.get("tested") is False for r in rows)
    near = sum(int(r.get("near_misses") or 0) for r in rows)
    false = sum(int(r.get("false_activations") or 0) for r in rows)
    print(
        f"{len(rows) + skipped} run(s){skip}, {n_coll} collision(s), {untested} not tested, "
        f"{near} near miss(es), {false} false activation(s); table: {out / 'results.csv'}"
    )


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run",
        help="run a scenario file (one concrete run or a small grid)",
        description="Runs each concrete scenario in closed loop; exit status 3 when the ego "
        "collided in a run.",
    )
    p.add_argument(
        "scenario",
        nargs="?",
        help="scenario file: hiyari TOML, or OpenSCENARIO .xosc (a scenario or a "
        "ParameterValueDistribution); optional with --sumocfg / --map (free city driving)",
    )
    add_world_options(p)
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
        "--dry-run",
        action="store_true",
        help="make every check a run makes before its first step (file, parameters, road, "
        "SUMO, Init actions, the actions they decide, ego stack) and list the runs; run and "
        "write nothing",
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    add_xosc_options(p)
    p.set_defaults(func=run, run_parser=p)


def add_world_options(p: argparse.ArgumentParser) -> None:
    """The world options of ``run`` and ``sweep``: a SUMO scenario or a map to drive in, and
    the warm-up of the scenario's demand before a .xosc storyboard starts."""
    world = p.add_mutually_exclusive_group()
    world.add_argument(
        "--sumocfg",
        help="drive inside this SUMO scenario (its net, demand, additional files and time "
        "window; hiyari adds only the ego and the scenario's actors). A .xosc file's: its net "
        "must be the conversion of the road the .xosc names ('hiyari net import road.xodr')",
    )
    world.add_argument(
        "--map",
        help="city runs: drive on this SUMO net (e.g. from 'hiyari net import map.osm') with "
        "generated vehicles and pedestrians",
    )
    p.add_argument(
        "--warmup",
        type=numbers.seconds(lo_open=False),
        default=None,
        help=".xosc with --sumocfg: seconds the scenario's demand runs before the storyboard "
        "starts (default: 0; a TOML city file gives its warmup_s)",
    )


def add_xosc_options(p: argparse.ArgumentParser) -> None:
    """The ego stack, parameter and clock options of ``run`` and ``sweep`` (TOML files:
    --perception and --environment override the file's; the others apply to .xosc runs,
    whose files do not say)."""
    p.add_argument(
        "--perception",
        choices=["perfect", "sensors", "none"],
        default=None,
        help="ego perception (default: the TOML file's; perfect for .xosc)",
    )
    p.add_argument(
        "--environment",
        default=None,
        help="sensor disturbance preset (default: the TOML file's; clear for .xosc)",
    )
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help=".xosc: set a top-level ParameterDeclaration, checked against its type and "
        "ValueConstraints (repeatable; as esmini's --param)",
    )
    p.add_argument(
        "--ego",
        default=None,
        metavar="NAME",
        help=".xosc: the entity the ego stack drives (default: the one with the property "
        "type=ego_vehicle, else the one named Ego or hero, any case)",
    )
    p.add_argument("--step-length", type=numbers.seconds(), default=0.05, help=".xosc: step, s")
    p.add_argument("--seed", type=numbers.seed(), default=1, help=".xosc: base seed")
    p.add_argument(
        "--max-duration",
        type=numbers.seconds(),
        default=600.0,
        help=".xosc: end a run here if its stop trigger has not fired, s",
    )
