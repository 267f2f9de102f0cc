"""Locate SUMO's binaries from the installed eclipse-sumo wheel and run them.

No system SUMO and no hand-set SUMO_HOME: the wheel's own folder is the SUMO home.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

from hiyari.errors import HiyariError


def sumo_home() -> Path:
    """The SUMO_HOME folder of the installed ``eclipse-sumo`` package."""
    try:
        import sumo
    except ImportError as exc:
        raise HiyariError("eclipse-sumo is not installed (pip install eclipse-sumo)") from exc
    return Path(sumo.SUMO_HOME)


def sumo_binary(name: str) -> Path:
    """Path of a SUMO executable such as ``netconvert`` or ``sumo`` from the wheel."""
    path = sumo_home() / "bin" / name
    if not path.exists():
        raise HiyariError(f"SUMO binary {name!r} not found in {path.parent}")
    return path


def sumo_env() -> dict[str, str]:
    """Environment for SUMO subprocesses: SUMO_HOME pointing at the wheel."""
    env = dict(os.environ)
    env["SUMO_HOME"] = str(sumo_home())
    return env


def run_sumo_tool(name: str, args: list[str], what: str) -> subprocess.CompletedProcess[str]:
    """Run a SUMO binary; on failure raise a one-line HiyariError naming ``what``.

    ``what`` describes the input (usually a file name) so the message says what was wrong.
    """
    proc = subprocess.run(
        [str(sumo_binary(name)), *args], capture_output=True, text=True, env=sumo_env()
    )
    if proc.returncode != 0:
        errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("Error")]
        detail = errors[0] if errors else (proc.stderr.strip().splitlines() or ["failed"])[-1]
        raise HiyariError(f"{what}: {name} failed: {detail}")
    return proc


def sumo_version() -> str:
    """Version string printed by the wheel's ``sumo`` binary."""
    proc = subprocess.run(
        [str(sumo_binary("sumo")), "--version"], capture_output=True, text=True, env=sumo_env()
    )
    first = proc.stdout.splitlines()[0] if proc.stdout else ""
    return first.replace("Eclipse SUMO sumo ", "").strip() or "unknown"
