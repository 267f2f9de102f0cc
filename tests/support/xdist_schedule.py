"""The suite's pytest-xdist scheduler (used by conftest.py): each test goes to whichever worker
is free, except that the tests of a module with a module-scoped fixture (a reference sweep, a
study, a recorded run, a browser) go to one worker together, which builds the fixture once.
Those groups are handed out first (the largest first), so that no long one is left for the
end. (pytest-xdist's own ``--dist loadgroup`` would do the grouping, but under pytest 9 its
group suffix no longer reaches the test ids.)

A worker that crashes (a segmentation fault in native code) is replaced. pytest-xdist 3.8's
scope scheduler then queues all the crashed worker's work again, finished units included,
each of which goes out as an empty run order that never completes, and the session waits for
ever (upstream issues 1371 and 1378, open). Here only its unfinished units are queued again,
without the test it crashed on (reported failed; a rerun would take the replacement down too).
"""

from __future__ import annotations

import functools
from pathlib import Path

import pytest
from xdist.scheduler import LoadScopeScheduling
from xdist.workermanage import WorkerController


class ModuleFixtureScheduling(LoadScopeScheduling):
    """Scope per test, or per module for modules with a module-scoped fixture."""

    def __init__(self, config: pytest.Config, log: object = None) -> None:
        super().__init__(config, log)
        self._root = config.rootpath

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


@functools.cache
def _has_module_fixture(path: Path) -> bool:
    return 'scope="module"' in path.read_text()
