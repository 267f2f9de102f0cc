"""Exit statuses of the ``hiyari`` command (table in docs/guide/cli.md).

A pipeline tells "the tool could not do its job" (1) from "the tool did its job and the
system under test failed" (3); an interrupt is the shell's usual 128 + signal number.
"""

from __future__ import annotations

#: Everything ran, and every verdict passed (or the command has no verdict).
OK = 0
#: Bad input or a failure: one line on stderr ("hiyari: error: ..."), nothing half-written.
ERROR = 1
#: The runs completed, and a verdict failed: an evaluate run not passed, an R157 condition
#: failed, a ``hiyari run`` with a collision of the ego.
VERDICT_FAIL = 3
#: A run's worker process died (a native crash, an abort, an out-of-memory kill): that run is
#: recorded as crashed (its seed, parameters and the signal), every other run is kept, and the
#: same command run again retries the crashed ones. Takes precedence over VERDICT_FAIL: the
#: verdict is incomplete.
RUNS_CRASHED = 4
#: Ctrl-C (SIGINT, 128 + 2): finished runs are kept, unfinished ones never look finished.
INTERRUPTED = 130
#: SIGTERM (128 + 15): as Ctrl-C.
TERMINATED = 143


def verdict(passed: bool, crashed: int = 0) -> int:
    """RUNS_CRASHED when ``crashed`` runs > 0, else OK when ``passed``, else VERDICT_FAIL."""
    if crashed:
        return RUNS_CRASHED
    return OK if passed else VERDICT_FAIL
