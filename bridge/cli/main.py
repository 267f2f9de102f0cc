"""The ``hiyari`` command: one subcommand module per job, errors as one line."""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import threading

from hiyari.bridge.cli import status
from hiyari.bridge.cli.first_run import first_run_note
from hiyari.bridge.cli.parser import Parser
from hiyari.errors import HiyariError, unmasked_interrupts
from hiyari.version import __version__

# Each module has register(subparsers) adding a parser whose defaults set func(args) -> int.
COMMAND_MODULES = [
    "hiyari.bridge.cli.commands.doctor",
    "hiyari.bridge.cli.commands.sim",
    "hiyari.bridge.cli.commands.demo",
    "hiyari.bridge.cli.commands.net",
    "hiyari.bridge.cli.commands.runs.run",
    "hiyari.bridge.cli.commands.runs.sweep",
    "hiyari.bridge.cli.commands.runs.replay",
    "hiyari.bridge.cli.commands.evaluation.boundary",
    "hiyari.bridge.cli.commands.evaluation.r157",
    "hiyari.bridge.cli.commands.sensors",
    "hiyari.bridge.cli.commands.evaluation.study",
    "hiyari.bridge.cli.commands.evaluation.evaluate",
    "hiyari.bridge.cli.commands.evaluation.ncap",
    "hiyari.bridge.cli.commands.evaluation.perception",
]


class Terminated(KeyboardInterrupt):
    """SIGTERM, delivered like Ctrl-C so that every ``finally`` and ``with`` unwinds
    (temporary folders removed, workers stopped, partial outputs discarded)."""


def _terminate(signum: int, frame: object) -> None:
    raise Terminated()


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser with every subcommand registered."""
    parser = Parser(prog="hiyari", description="Automated-driving safety evaluation on SUMO.")
    parser.add_argument("--version", action="version", version=f"hiyari {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit status (bridge.cli.status: 0 passed, 1 for a HiyariError
    or a usage error, 3 when a verdict failed, 130 on Ctrl-C, 143 on SIGTERM)."""
    # the one place that picks matplotlib's backend: files only, no display needed; set
    # without importing matplotlib, which most commands never load
    if "matplotlib" in sys.modules:
        sys.modules["matplotlib"].use("Agg")
    else:
        os.environ["MPLBACKEND"] = "Agg"
    previous = None
    if threading.current_thread() is threading.main_thread():  # where handlers may be set
        previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        args = build_parser().parse_args(argv)
        args.argv = list(sys.argv[1:] if argv is None else argv)  # the command as given
        first_run_note(args.command)
        with unmasked_interrupts():
            return int(args.func(args) or status.OK)
    except HiyariError as exc:
        print(f"hiyari: error: {exc}", file=sys.stderr)
        return status.ERROR
    except KeyboardInterrupt as exc:
        # a command may say what was kept and how to resume in the exception's message
        detail = f": {exc}" if str(exc) else ""
        print(f"hiyari: interrupted{detail}", file=sys.stderr)
        return status.TERMINATED if isinstance(exc, Terminated) else status.INTERRUPTED
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
