"""The ``hiyari`` command: one subcommand module per job, errors as one line."""

from __future__ import annotations

import argparse
import importlib
import sys

from hiyari import __version__
from hiyari.errors import HiyariError

# Each module has register(subparsers) adding a parser whose defaults set func(args) -> int.
COMMAND_MODULES = [
    "hiyari.bridge.cmd_doctor",
    "hiyari.bridge.cmd_sim",
    "hiyari.bridge.cmd_demo",
    "hiyari.bridge.cmd_net",
    "hiyari.bridge.cmd_run",
    "hiyari.bridge.cmd_sweep",
    "hiyari.bridge.cmd_replay",
    "hiyari.bridge.cmd_boundary",
    "hiyari.bridge.cmd_r157",
    "hiyari.bridge.cmd_sensors",
    "hiyari.bridge.cmd_study",
]


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser with every subcommand registered."""
    parser = argparse.ArgumentParser(
        prog="hiyari", description="Automated-driving safety evaluation on SUMO."
    )
    parser.add_argument("--version", action="version", version=f"hiyari {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit status (1 for a HiyariError, 130 on Ctrl-C)."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except HiyariError as exc:
        print(f"hiyari: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("hiyari: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
