"""numba's ``njit`` with an on-disk cache that concurrent processes cannot corrupt.

Every compiled kernel in hiyari is cached (``cache=True``) so that only the first run pays
for compilation. numba's cache is not safe when two processes compile different signatures of
one function at the same moment (numba issues #4807 and #10128): each reads the index, both
pick the same data-file number, and the index can end up pairing one signature with the
other's machine code. A later process that loads it calls code built for other argument types
and crashes. Test workers, ``-j N`` sweeps and Ray workers all compile concurrently on a fresh
install, so the index read-modify-write and the data read are serialised here with an advisory
file lock per cached function (``<function>.nbi.lock`` beside the index).

numba checks a cached kernel against its own source file only (its modification time and
size), but a kernel compiles the njit functions it calls from other modules into itself: after
an edit or a ``git pull`` that changes only a callee, the cache would keep running the old code.
So every hiyari kernel's cache is also stamped with the contents of all of hiyari's modules that
define kernels (:func:`kernel_sources_stamp`): a change in any of them recompiles them all.

No kernel asks numba to inline (``inline="always"``): numba inlines at the level of its own IR
and types each inlined body again at every call site, which made the trigger kernel take
about 90 of the 106 CPU seconds a fresh clone's first closed-loop run spent compiling. LLVM
still inlines small callees when it optimises the linked module, and the engine's cost per step
did not change (benchmarks/scenario_engine.py).
"""

from __future__ import annotations

import fcntl
import functools
import hashlib
import importlib.util
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from numba import njit
from numba.core.caching import Cache, IndexDataCacheFile

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

#: hiyari's top-level packages (each may live in its own folder: see pyproject's package-dir).
PACKAGES = ("hiyari", "hiyari.net", "hiyari.traffic", "hiyari.sensors", "hiyari.risk",
            "hiyari.bridge")  # fmt: skip


def kernel_sources_stamp(roots: Iterable[Path]) -> str:
    """sha256 over the path (relative to its root) and contents of every module below
    ``roots`` that imports ``hiyari.jit``, i.e. every module that defines kernels. Only
    package folders (with an ``__init__.py``) are entered below a root."""
    h = hashlib.sha256()
    for root in roots:
        for path in _modules(root):
            data = path.read_bytes()
            if b"hiyari.jit" in data and path.name != "jit.py":
                h.update(str(path.relative_to(root)).encode() + b"\0" + data + b"\0")
    return h.hexdigest()


def _modules(folder: Path) -> list[Path]:
    out = sorted(folder.glob("*.py"))
    for sub in sorted(p for p in folder.iterdir() if (p / "__init__.py").is_file()):
        out += _modules(sub)
    return out


@functools.cache
def _package_stamp() -> str:
    roots: list[Path] = []
    for name in PACKAGES:
        spec = importlib.util.find_spec(name)
        roots += [Path(p) for p in (spec.submodule_search_locations or ()) if p not in roots]
    # the subpackages' folders may sit inside hiyari's own (an installed wheel, or a clone
    # folder named hiyari taken as a namespace package): each is walked once
    top, *subs = roots
    return kernel_sources_stamp([top] + [r for r in subs if top not in r.parents])


def _stamped(init: Callable[..., None]) -> Callable[..., None]:
    @functools.wraps(init)
    def stamped_init(self: Cache, py_func: Callable[..., Any]) -> None:
        init(self, py_func)
        if py_func.__module__.split(".")[0] == "hiyari":
            cache_file = self._cache_file
            cache_file._source_stamp = (cache_file._source_stamp, _package_stamp())

    stamped_init.hiyari_stamped = True  # type: ignore[attr-defined]
    return stamped_init


if not getattr(Cache.__init__, "hiyari_stamped", False):
    Cache.__init__ = _stamped(Cache.__init__)


def cached(kernel: Any) -> bool:
    """True when the on-disk cache holds a build of ``kernel`` (an ``njit(cache=True)``
    function) for the current sources: no compilation is due for it."""
    return bool(kernel._cache._cache_file._load_index())
