"""The ``hiyari`` command: one subcommand module per job, errors as one line."""

from __future__ import annotations

import argparse
import importlib
import sys

from hiyari import __version__
from hiyari.errors import HiyariError

# Each module has register(subparsers) adding a parser whose defaults set func(args) -> int.
COMMAND_MODULES = [
    "hiyari.bridge.cli.commands.doctor",
    "hiyari.bridge.cli.commands.sim",
    "hiyari.bridge.cli.commands.demo",
    "hiyari.bridge.cli.commands.net",
    "hiyari.bridge.cli.commands.run",
    "hiyari.bridge.cli.commands.sweep",
    "hiyari.bridge.cli.commands.replay",
    "hiyari.bridge.cli.commands.boundary",
    "hiyari.bridge.cli.commands.r157",
    "hiyari.bridge.cli.commands.sensors",
    "hiyari.bridge.cli.commands.study",
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
    # the one place that picks matplotlib's backend: files only, no display needed
    import matplotlib

    matplotlib.use("Agg")
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
