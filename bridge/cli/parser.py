"""The command line's argument parser: a usage error is a HiyariError, and a command's options
may be added only when that command is used, so that ``hiyari --help`` and each command import
only the modules they need."""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable, Sequence
from typing import Any

from hiyari.errors import HiyariError


class DefaultsHelpFormatter(argparse.HelpFormatter):
    """argparse's help, with "(default: X)" after each option whose help does not already
    speak of its default (nothing is added for a default of None, False or empty: no
    value)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        default = action.default
        if (
            not action.option_strings
            or "default" in text.lower()
            or default is None
            or default is False
            or default is argparse.SUPPRESS
            or default in ([], "")
        ):
            return action.help
        return f"{text} (default: %(default)s)"


class Parser(argparse.ArgumentParser):
    """argparse, but a usage error is a HiyariError: one line, exit status 1; every option's
    help says its default (DefaultsHelpFormatter).

    ``setup(parser)``, when given, adds the parser's arguments the first time it parses or
    formats its help: for a command whose option choices and defaults come from modules that
    are slow to import (numba kernels, viser, SUMO), which the other commands should not pay.
    """

    def __init__(
        self, *args: Any, setup: Callable[[argparse.ArgumentParser], None] | None = None, **kw: Any
    ) -> None:
        kw.setdefault("formatter_class", DefaultsHelpFormatter)
        super().__init__(*args, **kw)
        self._setup = setup

    def _ready(self) -> None:
        setup, self._setup = self._setup, None
        if setup is not None:
            setup(self)

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        """argparse's, after the deferred set-up."""
        self._ready()
        return super().parse_known_args(args, namespace)

    def format_usage(self) -> str:
        """argparse's, after the deferred set-up."""
        self._ready()
        return super().format_usage()

    def format_help(self) -> str:
        """argparse's, after the deferred set-up."""
        self._ready()
        return super().format_help()

    def error(self, message: str) -> None:  # type: ignore[override]
        """Raise the usage error as a HiyariError (printed as one line by ``main``)."""
        # "argument --duration/-d: expected ..." -> "--duration: expected ..."
        option = re.sub(r"^argument (-[-\w]+)(?:/-[-\w]+)*: ", r"\1: ", message)
        if option != message:
            raise HiyariError(option)
        # main prints "hiyari: error:" already; name the subcommand only ("hiyari run: ...")
        raise HiyariError(f"{self.prog}: {message}" if " " in self.prog else message)
