"""Locate SUMO's binaries from the installed eclipse-sumo wheel, run them, and turn what SUMO
prints on failure into one line.

No system SUMO and no hand-set SUMO_HOME: the wheel's own folder is the SUMO home.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
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
    """Environment for SUMO subprocesses: SUMO_HOME pointing at the wheel, and PROJ's data
    (the wheel's ``data/proj``) for the geo projections of imported OpenStreetMap nets."""
    env = dict(os.environ)
    env["SUMO_HOME"] = str(sumo_home())
    env.update(proj_env())
    return env


def proj_env() -> dict[str, str]:
    """PROJ's data folder for SUMO (``PROJ_DATA`` and the older ``PROJ_LIB`` SUMO's PROJ
    reads): without it netconvert cannot project OpenStreetMap coordinates and SUMO prints
    "Cannot find proj.db" loading a geo-referenced net. Empty when the wheel has no proj data."""
    proj = sumo_home() / "data" / "proj"
    if not (proj / "proj.db").is_file():
        return {}
    return {"PROJ_DATA": str(proj), "PROJ_LIB": str(proj)}


def first_error(text: str) -> str:
    """The first ``Error:`` message SUMO printed, on one line (SUMO continues a message on
    lines starting with a space), with a count of the errors after it; '' when none."""
    messages: list[list[str]] = []
    for line in text.splitlines():
        if line.startswith("Error:"):
            messages.append([line[len("Error:") :].strip()])
        elif messages and line.startswith(" ") and len(messages) == 1:
            messages[0].append(line.strip())
    if not messages:
        return ""
    detail = " ".join(messages[0]).rstrip(".")
    more = len(messages) - 1
    return detail + (f" (and {more} more error{'s' * (more > 1)})" if more else "")


def run_sumo_tool(name: str, args: list[str], what: str) -> subprocess.CompletedProcess[str]:
    """Run a SUMO binary; on failure raise a one-line HiyariError naming ``what``.

    ``what`` describes the input (usually a file name) so the message says what was wrong.
    """
    proc = subprocess.run(
        [str(sumo_binary(name)), *args], capture_output=True, text=True, env=sumo_env()
    )
    if proc.returncode != 0:
        detail = first_error(proc.stderr) or (proc.stderr.strip().splitlines() or ["failed"])[-1]
        raise HiyariError(f"{what}: {name} failed: {detail}")
    return proc


def check_net_loads(net: str | os.PathLike[str]) -> None:
    """Load ``net`` in SUMO itself (no demand, no step); HiyariError naming the file with
    SUMO's first complaint when SUMO rejects it (a broken shape, an edge naming an unknown
    node ...), so nothing is built from a network SUMO would not run."""
    check_sumo_loads(["-n", str(net)], str(net), "SUMO cannot load the network")


def check_sumo_loads(inputs: list[str], culprit: str, what: str) -> None:
    """Load SUMO inputs (``-n net``, ``-c config`` ...) in a ``sumo`` subprocess without
    stepping; HiyariError ``"<culprit>: <what>: <SUMO's first error>"`` when SUMO rejects or
    crashes on them. Run before libsumo loads a user's files into this process: SUMO's loader
    crashes on some broken nets (a missing connection), which must not take hiyari down."""
    args = [*inputs, "--begin", "0", "--end", "0", "--no-step-log", "true", "--no-warnings", "true"]
    proc = subprocess.run(
        [str(sumo_binary("sumo")), *args], capture_output=True, text=True, env=sumo_env()
    )
    if proc.returncode < 0:
        name = signal.Signals(-proc.returncode).name
        raise HiyariError(f"{culprit}: {what}: SUMO crashed reading it ({name})")
    if proc.returncode != 0:
        detail = first_error(proc.stderr) or "SUMO exited with an error"
        raise HiyariError(f"{culprit}: {what}: {detail}")


class StderrTrap:
    """Catches what native code (libsumo) writes to file descriptor 2 during a call.

    libsumo prints every load error, and route errors met while stepping, on stderr itself
    before raising a bare "Process Error"; trapping them lets the caller report the first
    one, once, naming the user's file. Use ``with trap:`` around each native call (two
    ``dup2`` per call, about a microsecond); :meth:`take` returns what arrived since the
    last take. Python's own output (progress bars) between calls is not affected. The
    stderr restored after each call is the one at construction: one trap per simulation.
    """

    def __init__(self) -> None:
        self._file = tempfile.TemporaryFile(mode="w+b")  # noqa: SIM115 - closed in close()
        self._stderr = os.dup(2)
        self._seen = 0

    def __enter__(self) -> StderrTrap:
        sys.stderr.flush()
        os.dup2(self._file.fileno(), 2)
        return self

    def __exit__(self, *exc: object) -> None:
        os.dup2(self._stderr, 2)

    def take(self) -> str:
        """Text written since the last call ('' when none)."""
        size = os.fstat(self._file.fileno()).st_size
        if size == self._seen:
            return ""
        self._file.seek(self._seen)
        self._seen = size
        return self._file.read().decode(errors="replace")

    def close(self) -> None:
        """Release the file and the saved descriptor (safe to call twice)."""
        if not self._file.closed:
            os.close(self._stderr)
            self._file.close()


def sumo_version() -> str:
    """Version string printed by the wheel's ``sumo`` binary."""
    proc = subprocess.run(
        [str(sumo_binary("sumo")), "--version"], capture_output=True, text=True, env=sumo_env()
    )
    first = proc.stdout.splitlines()[0] if proc.stdout else ""
    return first.replace("Eclipse SUMO sumo ", "").strip() or "unknown"
