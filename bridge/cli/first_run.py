"""The note a first run prints: hiyari's kernels are compiled on first use and cached, which
takes minutes on a fresh install (or after the kernels' sources changed), and a progress bar's
first estimate would otherwise look like a hang."""

from __future__ import annotations

import sys

#: The commands that run simulations through the compiled kernels.
SIMULATING = frozenset({"demo", "run", "sweep", "r157", "evaluate", "ncap", "study", "perception"})


def first_run_note(command: str) -> None:
    """Print one line to stderr when ``command`` simulates and the kernels are not cached."""
    if command not in SIMULATING:
        return
    from hiyari.bridge.openscenario.engine.kernels.step_kernel import quiet_step
    from hiyari.jit import cached

    if not cached(quiet_step):
        print(
            "hiyari: first run: compiling the kernels (numba) and caching them, several minutes "
            "on 2 cores; progress estimates settle after it, and later runs start at once",
            file=sys.stderr,
            flush=True,
        )
