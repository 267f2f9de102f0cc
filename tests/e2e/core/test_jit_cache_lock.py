"""The compiled-kernel cache is serialised across processes (numba issues #4807 / #10128)."""

from __future__ import annotations

import fcntl
import os
import subprocess
import sys
import textwrap
import time

KERNEL = textwrap.dedent(
    """
    from hiyari.jit import njit

    @njit(cache=True)
    def twice(x):
        return 2 * x

    print(twice(21), twice(1.5))
    """
)


def _run(tmp_path, **kw):
    script = tmp_path / "kernel_mod.py"
    script.write_text(KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    return subprocess.Popen(
        [sys.executable, str(script)], env=env, stdout=subprocess.PIPE, text=True, **kw
    )


def test_a_process_waits_for_the_lock_before_it_writes_the_cache(tmp_path):
    first = _run(tmp_path)
    assert first.communicate(timeout=120)[0].split() == ["42", "3.0"]
    locks = list((tmp_path / "cache").rglob("*.nbi.lock"))
    assert len(locks) == 1, "the cached function has one lock file beside its index"
    with open(locks[0], "a") as held:
        fcntl.flock(held, fcntl.LOCK_EX)
        second = _run(tmp_path)
        time.sleep(4.0)
        assert second.poll() is None, "the cache was read while another process held the lock"
        fcntl.flock(held, fcntl.LOCK_UN)
    assert second.communicate(timeout=120)[0].split() == ["42", "3.0"]
    assert second.returncode == 0
