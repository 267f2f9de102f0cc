"""The suite's pytest-xdist scheduler (used by conftest.py): each test goes to whichever worker
is free, except that the tests of a module with a module-scoped fixture (a reference sweep, a
study, a recorded run, a browser) go to one worker together, which builds the fixture once.
Work is handed out longest first (by the seconds each test took before: the last run's
out/test-durations.csv over the estimates kept in tests/support/test_durations.csv), so that
no long test or group is left for the end while the other worker idles. (pytest-xdist's own
``--dist loadgroup`` would do the grouping, but under pytest 9 its group suffix no longer
reaches the test ids.)

A worker that crashes (a segmentation fault in native code) is replaced. pytest-xdist 3.8's
scope scheduler then queues all the crashed worker's work again, finished units included,
each of which goes out as an empty run order that never completes, and the session waits for
ever (upstream issues 1371 and 1378, open). Here only its unfinished units are queued again,
without the test it crashed on (reported failed; a rerun would take the replacement down too).
"""

from __future__ import annotations

import csv
import functools
from collections import OrderedDict
from pathlib import Path

import pytest
from xdist.scheduler import LoadScopeScheduling
from xdist.workermanage import WorkerController

#: Estimated seconds per test, kept with the suite (refreshed from out/test-durations.csv
#: when the suite changes much); a test in neither file counts as UNKNOWN_S.
ESTIMATES = Path(__file__).with_name("test_durations.csv")
UNKNOWN_S = 0.5


class ModuleFixtureScheduling(LoadScopeScheduling):
    """Scope per test, or per module for modules with a module-scoped fixture; the longest
    scopes first."""

    def __init__(self, config: pytest.Config, log: object = None) -> None:
        super().__init__(config, log)
        self._root = config.rootpath
        self._seconds = estimated_seconds(config.rootpath)
        self._ordered = False

    def _assign_work_unit(self, node: WorkerController) -> None:
        """Before the first unit goes out, order the queue by estimated seconds, longest first."""
        if not self._ordered:
            self._ordered = True
            self.workqueue = OrderedDict(
                sorted(self.workqueue.items(), key=lambda kv: -self.unit_seconds(kv[1]))
            )
        super()._assign_work_unit(node)

    def unit_seconds(self, unit: dict[str, bool]) -> float:
        return sum(self._seconds.get(nodeid, UNKNOWN_S) for nodeid in unit)

    def _split_scope(self, nodeid: str) -> str:
        module = nodeid.split("::", 1)[0]
        return module if _has_module_fixture(self._root / module) else nodeid

    def remove_node(self, node: WorkerController) -> str | None:
        """Forget ``node``; when it crashed, queue its unfinished work again (without the
        test it crashed on) and return that test's id."""
        workload = self.assigned_work.pop(node)
        pending = [nid for unit in workload.values() for nid, done in unit.items() if not done]
        if not pending:
            return None
        crashed = pending[0]
        for scope, unit in workload.items():
            if crashed in unit:
                unit[crashed] = True
            if not all(unit.values()):
                self.workqueue[scope] = unit
        for other in self.assigned_work:
            self._reschedule(other)
        return crashed


def make_scheduler(config: pytest.Config, log: object) -> ModuleFixtureScheduling | None:
    """The scheduler for ``-n N`` with the default ``--dist load``; None for other modes."""
    if config.getvalue("dist") != "load":
        return None
    return ModuleFixtureScheduling(config, log)


def estimated_seconds(root: Path) -> dict[str, float]:
    """Seconds per test id: the kept estimates, overridden by the last run's measurements
    (a run of some files only rewrites out/test-durations.csv with those)."""
    seconds: dict[str, float] = {}
    for path in (ESTIMATES, root / "out" / "test-durations.csv"):
        try:
            with path.open(newline="") as f:
                seconds.update((row["test"], float(row["seconds"])) for row in csv.DictReader(f))
        except (OSError, KeyError, ValueError):
            continue
    return seconds


@functools.cache
def _has_module_fixture(path: Path) -> bool:
    return 'scope="module"' in path.read_text()
