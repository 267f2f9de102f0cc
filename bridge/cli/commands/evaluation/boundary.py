"""``hiyari boundary {cut-in,cut-out,decel}``: C&C Preventable boundary datasheets (CSV + PNG)."""

from __future__ import annotations

import argparse
import time

from hiyari.bridge.cli.outputs import output_folder
from hiyari.risk.cc.boundary import (
    Grid,
    cut_in_datasheet,
    cut_out_datasheet,
    decel_datasheet,
)
from hiyari.risk.cc.model import CONVENTIONS, CCParams

#: The scenarios whose driver-model conventions a command takes.
ALL_SCENARIOS = ("cut-in", "cut-out", "decel")


def add_model_options(
    parser: argparse.ArgumentParser, scenarios: tuple[str, ...] = ALL_SCENARIOS
) -> None:
    """``--aeb``, the driver-model conventions of ``scenarios`` and ``--param NAME=VALUE``
    (any CCParams field), shared with ``hiyari r157``. Convention defaults are docs/models.md's."""
    parser.add_argument("--aeb", action="store_true", help="AEB-equipped C&C driver")
    conv = parser.add_argument_group(
        "driver-model conventions (defaults: docs/models.md; shown on every datasheet)"
    )
    if "cut-in" in scenarios:
        conv.add_argument(
            "--danger-at",
            choices=CONVENTIONS["judgement"],
            default=None,
            help="cut-in danger judgement: wander exit + 0.4 s (time), at wander + 0.72 m "
            "(position), or at the first lateral overlap with the ego (overlap)",
        )
        conv.add_argument(
            "--above-ttc",
            choices=CONVENTIONS["above_ttc"],
            default=None,
            help="cut-in with TTC >= 2 s at danger judgement: react when it falls to 2 s "
            "(wait) or treat the cut-in as not critical and end the scenario (end)",
        )
    if "cut-out" in scenarios:
        conv.add_argument(
            "--cut-out-perception",
            choices=["yes", "no"],
            default=None,
            help="cut-out: add the 0.4 s perception delay after the cut-out judgement",
        )
    if "decel" in scenarios:
        conv.add_argument(
            "--decel-perception",
            choices=CONVENTIONS["decel_perception"],
            default=None,
            help="deceleration: 0.4 s perception delay after the lead's brake onset always, "
            "never, or only above hard_braking_mps2 (5 m/s²)",
        )
    if "cut-in" in scenarios:
        conv.add_argument(
            "--contact",
            choices=CONVENTIONS["contact"],
            default=None,
            help="cut-in contact: rectangles along the Annex G heading (heading) or the lane "
            "(lane)",
        )
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override a C&C model parameter, e.g. max_decel_g=0.7 (repeatable)",
    )


_CONVENTION_OPTIONS = {
    "danger_at": "judgement",
    "above_ttc": "above_ttc",
    "cut_out_perception": "cut_out_perception",
    "decel_perception": "decel_perception",
    "contact": "contact",
}


def model_params(args: argparse.Namespace) -> CCParams:
    """CCParams from ``--aeb``, the convention options and ``--param`` overrides."""
    overrides = list(args.param) + (["aeb=true"] if args.aeb else [])
    for option, field in _CONVENTION_OPTIONS.items():
        value = getattr(args, option, None)
        if value is not None:
            overrides.append(
                f"{field}={'true' if value == 'yes' else 'false' if value == 'no' else value}"
            )
    return CCParams().with_overrides(overrides)


def _grid(text: str, name: str) -> Grid:
    return Grid.parse(text, name)


def run(args: argparse.Namespace) -> int:
    # matplotlib is loaded when a datasheet is drawn, not for the other commands
    from hiyari.bridge.studies.report.datasheets import plot_cut_in, plot_cut_out, plot_decel

    params = model_params(args)
    out = output_folder(args.out)
    started = time.perf_counter()
    if args.scenario == "cut-in":
        sheet = cut_in_datasheet(
            _grid(args.ve, "--ve"),
            _grid(args.dv, "--dv"),
            _grid(args.vy, "--vy"),
            params,
            resolution_m=args.resolution,
        )
        paths = [
            sheet.write_csv(out / "cut_in_boundary.csv"),
            plot_cut_in(sheet, out / "cut_in_boundary.png"),
        ]
        rows = sheet.ve0_kmh.size
    elif args.scenario == "cut-out":
        sheet = cut_out_datasheet(
            _grid(args.ve, "--ve"), _grid(args.vy, "--vy"), params, resolution_m=args.resolution
        )
        paths = [
            sheet.write_csv(out / "cut_out_boundary.csv"),
            plot_cut_out(sheet, out / "cut_out_boundary.png"),
        ]
        rows = sheet.ve0_kmh.size
    else:
        sheet = decel_datasheet(_grid(args.ve, "--ve"), _grid(args.gx, "--gx"), params)
        paths = [
            sheet.write_csv(out / "decel_map.csv"),
            plot_decel(sheet, out / "decel_map.png"),
        ]
        rows = sheet.ve0_kmh.size
    print(
        f"{args.scenario}: {rows} scenarios in {time.perf_counter() - started:.2f} s "
        f"({'with' if params.aeb else 'without'} AEB)\n   {params.convention_note()}"
    )
    for path in paths:
        print(f"   {path}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "boundary",
        help="C&C driver Preventable boundary datasheets (JAMA Fig. 26/28/30)",
        description="Preventable boundaries of the competent and careful driver as CSV and PNG.",
    )
    scenarios = p.add_subparsers(dest="scenario", required=True, metavar="SCENARIO")
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("-o", "--out", default="out/boundary", help="output folder")
    common.add_argument("--ve", default="10:130:1", help="ego speeds Ve0, km/h start:stop:step")
    # each scenario takes its own conventions only: a cut-out option on a cut-in is a mistake
    cut_in = scenarios.add_parser(
        "cut-in", parents=[common], help="boundary dx0 per (Ve0, Vo0, Vy)"
    )
    cut_in.add_argument("--dv", default="0:60:1", help="relative speeds Ve0 - Vo0, km/h")
    cut_in.add_argument("--vy", default="0.1:3:0.1", help="lateral velocities, m/s")
    cut_in.add_argument("--resolution", type=float, default=0.1, help="boundary grid, m")
    add_model_options(cut_in, ("cut-in",))
    cut_out = scenarios.add_parser("cut-out", parents=[common], help="boundary dx0_f per (Ve0, Vy)")
    cut_out.add_argument("--vy", default="0.1:3:0.1", help="lateral velocities, m/s")
    cut_out.add_argument("--resolution", type=float, default=0.1, help="boundary grid, m")
    add_model_options(cut_out, ("cut-out",))
    decel = scenarios.add_parser(
        "decel", parents=[common], help="Preventable map over (Ve0, Gx_max)"
    )
    decel.add_argument("--gx", default="0.01:1:0.01", help="lead decelerations, g")
    add_model_options(decel, ("decel",))
    p.set_defaults(func=run)
