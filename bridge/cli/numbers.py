"""Number options of the command line: finite values within a stated range, or a one-line
error (nan, inf, negative or absurdly large values never reach a simulation)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

#: Seeds go to SUMO (a C int) and numpy.
MAX_SEED = 2**31 - 1
#: Longest simulated span any command accepts, s (a year: far beyond any study).
MAX_SECONDS = 366 * 86400.0
#: Highest generated demand, actors per hour (a busy motorway carries ~2,000 per lane).
MAX_PER_HOUR = 100_000.0


def number(
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = False,
    integer: bool = False,
    unit: str = "",
    what: str = "",
) -> Callable[[str], float | int]:
    """An argparse ``type``: the text as a finite float (or int) within ``lo``..``hi``
    (``lo`` excluded when ``lo_open``); ArgumentTypeError saying the allowed range otherwise.
    ``what`` names the quantity in the message ("the step length")."""
    low = "" if lo is None else f"{'>' if lo_open else '>='} {lo:.10g}"
    high = "" if hi is None else f"<= {hi:.10g}"
    bounds = " and ".join(b for b in (low, high) if b)
    kind = "an integer" if integer else "a finite number"
    want = f"{kind}{' ' + bounds if bounds else ''}{' ' + unit if unit else ''}"
    if what:
        want = f"{what} as {want}"

    def parse(text: str) -> float | int:
        try:
            value: float | int = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {want}, got {text!r}") from None
        ok = math.isfinite(value)
        ok = ok and (lo is None or (value > lo if lo_open else value >= lo))
        ok = ok and (hi is None or value <= hi)
        if not ok:
            raise argparse.ArgumentTypeError(f"expected {want}, got {text!r}")
        return value

    parse.__name__ = "integer" if integer else "number"  # argparse names the type in errors
    return parse


def seconds(lo_open: bool = True) -> Callable[[str], float]:
    """A simulated duration: > 0 s (or >= 0 s) and at most a year."""
    return number(0.0, MAX_SECONDS, lo_open=lo_open, unit="s")


def per_hour() -> Callable[[str], float]:
    """A demand rate, 0 .. MAX_PER_HOUR per hour."""
    return number(0.0, MAX_PER_HOUR, unit="per hour")


def seed() -> Callable[[str], int]:
    """A random seed, 0 .. 2^31 - 1."""
    return number(0, MAX_SEED, integer=True)


def count(lo: int = 1, hi: int | None = None) -> Callable[[str], int]:
    """A whole number of things (workers, runs, frames), ``lo`` .. ``hi``."""
    return number(lo, hi, integer=True)
