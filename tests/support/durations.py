"""Every test's duration in a file that outlives the run, and the tests over the budget.

The suite must stay under 6 minutes on 2 cores with no test over 30 s; CI and developers read
out/test-durations.csv (setup + call + teardown per test, slowest first) to see where the
time goes. Under pytest-xdist the controller receives every worker's reports.
"""

from __future__ import annotations

import csv
from collections import defaultdict
from pathlib import Path

import pytest

#: seconds a single test may take (setup + call + teardown) before the summary names it
BUDGET_S = 30.0


class DurationLog:
    """A pytest plugin: sums each test's phases and writes them when the session ends."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.seconds: dict[str, float] = defaultdict(float)

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        self.seconds[report.nodeid] += report.duration

    def pytest_terminal_summary(self, terminalreporter) -> None:  # noqa: ANN001 - pytest's type
        rows = sorted(self.seconds.items(), key=lambda kv: -kv[1])
        if not rows:
            return
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with self.path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["seconds", "test"])
            w.writerows((f"{s:.2f}", nodeid) for nodeid, s in rows)
        slow = [(n, s) for n, s in rows if s > BUDGET_S]
        terminalreporter.write_line(
            f"test durations: {self.path} ({len(rows)} tests, total {sum(self.seconds.values()):.0f} s,"
            f" {len(slow)} over {BUDGET_S:.0f} s)"
        )
        for nodeid, s in slow:
            terminalreporter.write_line(f"  {s:6.1f} s  {nodeid}")
