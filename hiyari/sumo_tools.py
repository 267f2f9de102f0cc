"""Locate SUMO's binaries from the installed eclipse-sumo wheel, run them, and turn what SUMO
prints on failure into one line.

No system SUMO and no hand-set SUMO_HOME: the wheel's own folder is the SUMO home.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterator
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
    args = ["-n", str(net), "--begin", "0", "--end", "0", "--no-step-log", "true"]
    proc = subprocess.run(
        [str(sumo_binary("sumo")), *args, "--no-warnings", "true"],
        capture_output=True,
        text=True,
        env=sumo_env(),
    )
    if proc.returncode != 0:
        detail = first_error(proc.stderr) or "SUMO exited with an error"
        raise HiyariError(f"{net}: SUMO cannot load the network: {detail}")


@contextlib.contextmanager
def captured_stderr() -> Iterator[Callable[[], str]]:
    """Send what native code (libsumo) writes to file descriptor 2 into a temporary file for
    the duration of the block; yields a function returning the text captured so far.

    libsumo prints every load error on stderr itself, before raising a bare "Process Error";
    capturing them lets the caller report the first one, once, naming the user's file.
    """
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+b") as sink:
        os.dup2(sink.fileno(), 2)

        def text() -> str:
            sink.flush()
            sink.seek(0)
            return sink.read().decode(errors="replace")

        try:
            yield text
        finally:
            os.dup2(saved, 2)
            os.close(saved)


def sumo_version() -> str:
    """Version string printed by the wheel's ``sumo`` binary."""
    proc = subprocess.run(
        [str(sumo_binary("sumo")), "--version"], capture_output=True, text=True, env=sumo_env()
    )
    first = proc.stdout.splitlines()[0] if proc.stdout else ""
    return first.replace("Eclipse SUMO sumo ", "").strip() or "unknown"
