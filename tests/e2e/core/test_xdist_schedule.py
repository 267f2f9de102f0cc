"""The suite's pytest-xdist scheduler when a worker crashes: a small suite run in a
subprocess on two workers, one test of which kills its worker (as a segmentation fault in
native code would), ends instead of waiting for ever, reports that test failed once, and runs
every other test, the tests of a module with a module-scoped fixture on one worker."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from paths import REPO_ROOT

TESTS = REPO_ROOT / "tests" / "support"  # where xdist_schedule.py lives

CONFTEST = f"""
import sys
sys.path.insert(0, {str(TESTS)!r})
from xdist_schedule import make_scheduler

def pytest_xdist_make_scheduler(config, log):
    return make_scheduler(config, log)
"""

GROUPED = """
import os
import pytest

@pytest.fixture(scope="module")
def worker():
    return os.environ["PYTEST_XDIST_WORKER"]

@pytest.mark.parametrize("k", range(4))
def test_grouped(worker, k):
    assert os.environ["PYTEST_XDIST_WORKER"] == worker
"""

SINGLES = """
import os
import time

def test_before():
    time.sleep(0.2)

def test_crash():
    os.abort()

def test_after():
    time.sleep(0.2)
"""

MORE = "\n".join(f"def test_more_{k}():\n    pass\n" for k in range(8))


def test_a_crashed_worker_is_replaced_and_the_run_ends(tmp_path: Path) -> None:
    (tmp_path / "conftest.py").write_text(CONFTEST)
    (tmp_path / "test_grouped.py").write_text(GROUPED)
    (tmp_path / "test_a_crash.py").write_text(SINGLES)  # early in the queue
    (tmp_path / "test_more.py").write_text(MORE)
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-n", "2", "-p", "no:cacheprovider", "-rf", "-v"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,  # the unmended scheduler waits for ever here
    )
    out = run.stdout + run.stderr
    assert run.returncode == 1, out
    assert re.search(r"\b1 failed, 14 passed\b", out), out
    assert "replacing crashed worker" in out
    lines = out.splitlines()
    started = [ln for ln in lines if ln.startswith("test_a_crash.py::test_crash")]
    assert len(started) == 1  # run once, not again on the replacement worker
    assert sum("FAILED test_a_crash.py::test_crash" in ln for ln in lines) == 2  # run, summary
