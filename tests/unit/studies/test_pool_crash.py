"""The campaign pool: a worker that dies in a run (signal, abort, plain exit) loses that run
only; the run's result is a Crashed naming the signal, a new worker takes the rest; runs go
to worker processes unless in_process is asked for."""

from __future__ import annotations

import os
import signal

import pytest

from hiyari.bridge.studies.pool import Crashed, PoolOptions, run_all


def _task(job: tuple[str, int]) -> tuple[int, int]:
    """(value squared, pid) or die as ``job`` says."""
    how, value = job
    if how == "segv":
        os.kill(os.getpid(), signal.SIGSEGV)
    elif how == "abort":
        os.abort()
    elif how == "exit":
        os._exit(3)
    elif how == "raise":
        raise ValueError(f"bad value {value}")
    return value * value, os.getpid()


def test_dead_workers_lose_one_run_each_and_are_replaced():
    jobs = [("ok", 1), ("segv", 2), ("ok", 3), ("abort", 4), ("exit", 5), ("ok", 6), ("ok", 7)]
    out = dict(run_all(_task, jobs, PoolOptions(workers=2)))
    assert sorted(out) == list(range(7))
    assert out[1] == Crashed("worker process died of SIGSEGV (signal 11)", signal.SIGSEGV)
    assert out[3] == Crashed("worker process died of SIGABRT (signal 6)", signal.SIGABRT)
    assert out[4].signal is None and "exited with status 3" in str(out[4])
    assert [out[i][0] for i in (0, 2, 5, 6)] == [1, 9, 36, 49]
    # every run in a worker, never here; three workers died, so more than two served
    pids = {out[i][1] for i in (0, 2, 5, 6)}
    assert os.getpid() not in pids


def test_one_worker_is_a_worker_and_in_process_is_here():
    jobs = [("ok", 2), ("ok", 3)]
    (_, (_, pid1)), (_, (_, pid2)) = run_all(_task, jobs, PoolOptions(workers=1))
    assert pid1 == pid2 != os.getpid()
    here = dict(run_all(_task, jobs, PoolOptions(workers=4, in_process=True)))
    assert here == {0: (4, os.getpid()), 1: (9, os.getpid())}


def test_an_exception_in_a_run_stops_the_pool_and_is_raised():
    with pytest.raises(ValueError, match="bad value 2"):
        list(run_all(_task, [("ok", 1), ("raise", 2), ("ok", 3)], PoolOptions(workers=2)))


NO_CORE_PROBE = """
import os, resource, sys
resource.setrlimit(resource.RLIMIT_CORE, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
os.environ["HIYARI_TEST_CRASH_RUN"] = "0"
from hiyari.bridge.studies.pool import Crashed, PoolOptions, run_all
out = dict(run_all(abs, [-1, -2], PoolOptions(workers=1)))
sys.exit(0 if isinstance(out[0], Crashed) and out[1] == 2 else 1)
"""


def test_the_crash_hook_writes_no_core_file(tmp_path):
    """The test-only crash hook kills its worker without a core file even where core dumps
    are on (a core of a process with hiyari loaded is ~300 MB in the working folder), and
    the suite itself runs with core files off."""
    import resource
    import subprocess
    import sys

    assert resource.getrlimit(resource.RLIMIT_CORE)[0] == 0  # tests/conftest.py
    if resource.getrlimit(resource.RLIMIT_CORE)[1] != resource.RLIM_INFINITY:
        pytest.skip("core dumps cannot be turned on here (hard limit)")
    proc = subprocess.run([sys.executable, "-c", NO_CORE_PROBE], cwd=tmp_path, timeout=120)
    assert proc.returncode == 0
    assert list(tmp_path.iterdir()) == []
