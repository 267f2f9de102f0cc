"""The note a first run prints: hiyari's kernels are compiled on first use and cached, which
takes minutes on a fresh install (or after the kernels' sources changed), and a progress bar's
first estimate would otherwise look like a hang.

The note is printed when numba actually starts compiling (a cache miss), not when the command
starts: a command that stops on bad input before its first simulation step says only its one
error line, cold cache or not.
"""

from __future__ import annotations

import sys
from typing import TextIO

from numba.core import event

#: The commands that run simulations through the compiled kernels.
SIMULATING = frozenset({"demo", "run", "sweep", "r157", "evaluate", "ncap", "study", "perception"})

NOTE = (
    "hiyari: first run: compiling the kernels (numba) and caching them, several minutes "
    "on 2 cores; progress estimates settle after it, and later runs start at once"
)


def kernels_cached() -> bool:
    """Whether the closed loop's step kernel, the first every simulation compiles, is in the
    on-disk cache for the current sources."""
    from hiyari.bridge.openscenario.engine.kernels.step_kernel import quiet_step
    from hiyari.jit import cached

    return cached(quiet_step)


class CompileNote(event.Listener):
    """Prints :data:`NOTE` once, at the first compilation this process starts (a worker forked
    from the command inherits the listener and says it once for itself)."""

    def __init__(self, stream: TextIO | None = None) -> None:
        self.stream = stream
        self.said = False

    def on_start(self, ev: event.Event) -> None:
        if not self.said:
            self.said = True
            print(NOTE, file=self.stream or sys.stderr, flush=True)

    def on_end(self, ev: event.Event) -> None:
        pass


def first_run_note(command: str) -> CompileNote | None:
    """Arrange for :data:`NOTE` on stderr at the first kernel compilation of ``command``, when
    it is a command that simulates and the kernels are not cached (a fresh install, or sources
    changed; a late compilation of one rare signature is not worth the note); returns the
    listener registered (None when not)."""
    if command not in SIMULATING or kernels_cached():
        return None
    listener = CompileNote()
    event.register("numba:compile", listener)
    return listener
