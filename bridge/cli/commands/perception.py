"""``hiyari perception``: JAMA perception and vehicle-motion disturbances (coverage, sweeps,
grip use, blind spots)."""

from __future__ import annotations

import argparse
from pathlib import Path


def _coverage(args: argparse.Namespace) -> int:
    from hiyari.bridge.perception.coverage_run import parse_sensors, write_coverage

    text, paths = write_coverage(parse_sensors(args.sensors), Path(args.out))
    print(text)
    for p in paths.values():
        print(f"written: {p}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "perception", help="JAMA perception / vehicle-motion disturbances (principle coverage)"
    )
    psub = p.add_subparsers(dest="perception_command", required=True, metavar="SUBCOMMAND")
    c = psub.add_parser(
        "coverage",
        help="which JAMA principles each simulated disturbance exercises, per sensor and merged",
    )
    c.add_argument("--sensors", default="camera,radar,lidar", help="comma-separated sensors")
    c.add_argument("-o", "--out", default="out/perception", help="output folder")
    c.set_defaults(func=_coverage)
