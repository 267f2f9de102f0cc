"""numba's ``njit`` with an on-disk cache that concurrent processes cannot corrupt.

Every compiled kernel in hiyari is cached (``cache=True``) so that only the first run pays
for compilation. numba's cache is not safe when two processes compile different signatures of
one function at the same moment (numba issues #4807 and #10128): each reads the index, both
pick the same data-file number, and the index can end up pairing one signature with the
other's machine code. A later process that loads it calls code built for other argument types
and crashes. Test workers, ``-j N`` sweeps and Ray workers all compile concurrently on a fresh
install, so the index read-modify-write and the data read are serialised here with an advisory
file lock per cached function (``<function>.nbi.lock`` beside the index).
"""

from __future__ import annotations

import fcntl
import functools
from collections.abc import Callable
from typing import Any

from numba import njit
from numba.core.caching import IndexDataCacheFile

__all__ = ["njit"]


def _under_lock(method: Callable[..., Any], mode: int) -> Callable[..., Any]:
    @functools.wraps(method)
    def locked(self: IndexDataCacheFile, *args: Any) -> Any:
        with open(self._index_path + ".lock", "a") as lock:
            fcntl.flock(lock, mode)
            return method(self, *args)

    locked.hiyari_locked = True  # type: ignore[attr-defined]
    return locked


if not getattr(IndexDataCacheFile.save, "hiyari_locked", False):
    IndexDataCacheFile.save = _under_lock(IndexDataCacheFile.save, fcntl.LOCK_EX)
    IndexDataCacheFile.load = _under_lock(IndexDataCacheFile.load, fcntl.LOCK_SH)
