"""What an assessor needs to trace a catalogue report back to its run: when, from which code
(git commit, package versions), with which options, seeds and logical parameter ranges, in the
units people read (km/h for speeds, g beside m/s² for decelerations; SI inside).
"""

from __future__ import annotations

import platform
import subprocess
from dataclasses import fields
from datetime import UTC, datetime
from pathlib import Path

from hiyari.bridge.studies.catalogue.evaluation.campaign import CatalogueOptions
from hiyari.bridge.studies.catalogue.evaluation.expectation import IMPACT_TOLERANCE
from hiyari.bridge.studies.catalogue.space.parameters import Ranges
from hiyari.risk.cc.model import CCParams
from hiyari.units import G, mps_to_kmh

#: Catalogue parameters and range fields by name: (label, unit). Speeds are shown in km/h,
#: accelerations in m/s² with g beside them; everything else in its SI unit.
UNITS: dict[str, tuple[str, str]] = {
    "ego_speed": ("ego speed", "km/h"),
    "speed_delta": ("speed difference (other - ego)", "km/h"),
    "ahead_speed_delta": ("speed difference, vehicles ahead", "km/h"),
    "behind_speed_delta": ("speed difference, vehicles behind", "km/h"),
    "gap": ("gap", "m"),
    "lateral_speed": ("lateral speed", "m/s"),
    "decel": ("deceleration", "m/s²"),
    "accel": ("acceleration", "m/s²"),
    "lead_thw": ("ego's time headway to its lead", "s"),
    "plus_one_gap": ("gap lead to +1", "m"),
    "plus_one_speed": ("+1 speed", "x ego speed"),
    "chain_plus_one_speed": ("+1 speed, §4.1.3 chains", "x ego speed"),
    "ego_lateral_speed": ("ego's lateral speed (its lane change)", "m/s"),
    "event_time": ("manoeuvre start", "s"),
    "ego_event_time": ("ego's lane change start", "s"),
    "duration": ("simulated time per run", "s"),
    "junction_speed": ("approach speed at the junction", "km/h"),
    "arrival_offset": ("other's arrival relative to the ego's", "s"),
    "junction_arrival": ("ego reaches the junction entry at", "s"),
}


def in_user_units(name: str, value: float) -> str:
    """One SI value of parameter ``name`` as people read it: "113.5 km/h", "4.90 m/s² (0.50 g)"."""
    unit = UNITS.get(name, (name, ""))[1]
    if unit == "km/h":
        return f"{mps_to_kmh(value):.1f} km/h"
    if unit == "m/s²":
        return f"{value:.2f} m/s² ({value / G:.2f} g)"
    if unit == "x ego speed":
        return f"{value:.2f} x ego speed"
    return f"{value:.2f} {unit}".rstrip()


def format_params(params: dict[str, float]) -> str:
    """A concrete run's parameters (SI) as one line in users' units."""
    return "; ".join(f"{UNITS.get(k, (k, ''))[0]} {in_user_units(k, v)}" for k, v in params.items())


def format_ranges(ranges: Ranges) -> dict[str, str]:
    """Every logical range (and fixed timing) of ``ranges`` by label, in users' units."""
    out = {}
    for f in fields(ranges):
        value = getattr(ranges, f.name)
        label = UNITS.get(f.name, (f.name, ""))[0]
        if isinstance(value, tuple):
            lo, hi = (in_user_units(f.name, v) for v in value)
            out[label] = f"{lo} to {hi}"
        else:
            out[label] = in_user_units(f.name, value)
    return out


def versions() -> dict[str, str]:
    """Versions of hiyari, Python, numpy and SUMO (the installed distributions)."""
    from importlib.metadata import PackageNotFoundError, version

    import numpy

    from hiyari.version import __version__

    out = {"hiyari": __version__, "python": platform.python_version(), "numpy": numpy.__version__}
    for dist in ("eclipse-sumo", "libsumo"):
        try:
            out[dist] = version(dist)
        except PackageNotFoundError:  # not installed from this distribution: not listed
            continue
    return out


def git_commit(folder: Path | None = None) -> str:
    """The commit of the hiyari source checkout ("<sha> (uncommitted changes)" when dirty),
    or why there is none."""
    import hiyari.version

    where = folder or Path(hiyari.version.__file__).resolve().parent
    try:
        sha = subprocess.run(["git", "-C", str(where), "rev-parse", "HEAD"], capture_output=True,
                             text=True, timeout=10, check=True).stdout.strip()  # fmt: skip
        dirty = subprocess.run(["git", "-C", str(where), "status", "--porcelain",
                                "--untracked-files=no"], capture_output=True, text=True,
                               timeout=10, check=True).stdout.strip()  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return "not available (hiyari is not run from a git checkout)"
    return f"{sha} (uncommitted changes)" if dirty else sha


def run_configuration(options: CatalogueOptions, command: str, wall_s: float | None,
                      structures: Path) -> dict[str, str]:  # fmt: skip
    """The report's run-configuration table: date, command, code, options, seeds, ranges."""
    run = options.run
    conf = {
        "date (UTC)": datetime.now(UTC).isoformat(timespec="seconds"),
        "command": command,
        "git commit": git_commit(),
        **{f"version {k}": v for k, v in versions().items()},
        "catalogue": options.catalogue,
        "cells": ", ".join(options.only) + " (--cells)" if options.only else "all applicable",
        "stack": run.stack or "hiyari default (perception -> Kalman fusion -> ACC + AEB)",
        "perception": run.perception,
        "runs per cell": str(options.runs_per_cell),
        "seeds": f"{options.seed}: per cell s = crc32(cell key) xor {options.seed} seeds the "
        "scrambled Sobol sampling of its runs; run i of the cell runs SUMO with seed s + i",
        "simulation step": f"{run.step_length:g} s",
        "AEB actuation delay": f"{run.aeb_delay:g} s",
        "pass rule": "no collision where the C&C driver avoids one (Preventable); elsewhere a "
        f"relative impact speed at most the C&C driver's + {IMPACT_TOLERANCE:g} m/s",
        "C&C reference driver": CCParams().convention_note(),
        "workers / backend": f"{options.pool.workers} / {options.pool.backend}",
        "structures folder": str(structures),
    }
    if wall_s is not None:
        conf["wall time of this invocation"] = f"{wall_s:.1f} s"
    conf.update({f"range: {k}": v for k, v in format_ranges(options.ranges).items()})
    return conf
