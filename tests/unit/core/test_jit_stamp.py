"""The kernels' cache stamp: a kernel compiles the njit functions it calls from other modules
into itself, so its cache must go stale when any kernel module changes, not only its own."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from hiyari.jit import _package_stamp, kernel_sources_stamp


def _package(root: Path) -> Path:
    (root / "pkg").mkdir(parents=True)
    (root / "pkg" / "__init__.py").write_text("")
    (root / "pkg" / "kernel.py").write_text("from hiyari.jit import njit\nK = 1\n")
    (root / "pkg" / "plain.py").write_text("P = 1\n")
    (root / "notes").mkdir()  # not a package: never entered
    (root / "notes" / "k.py").write_text("from hiyari.jit import njit\n")
    return root


def test_the_stamp_follows_kernel_modules_only(tmp_path: Path) -> None:
    root = _package(tmp_path)
    before = kernel_sources_stamp([root])
    (root / "pkg" / "plain.py").write_text("P = 2\n")
    (root / "notes" / "k.py").write_text("from hiyari.jit import njit\nX = 2\n")
    assert kernel_sources_stamp([root]) == before
    (root / "pkg" / "kernel.py").write_text("from hiyari.jit import njit\nK = 2\n")
    assert kernel_sources_stamp([root]) != before


PROBE = """
import json, sys
import hiyari.jit as jit
if sys.argv[1] != "same":
    jit._package_stamp = lambda: "another kernel module"
import numpy as np
from hiyari.risk.sct.plan_kernel import _overlap_depth
q = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_overlap_depth(q, q + 0.5)
s = _overlap_depth.stats
print(json.dumps([sum(s.cache_hits.values()), sum(s.cache_misses.values())]))
"""


def _compile(cache: Path, stamp: str) -> tuple[int, int]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    out = subprocess.run([sys.executable, "-c", PROBE, stamp], env=env, capture_output=True,
                         text=True, check=True).stdout  # fmt: skip
    hits, misses = json.loads(out)
    return hits, misses


def test_a_changed_kernel_module_recompiles_every_kernel(tmp_path: Path) -> None:
    assert len(_package_stamp()) == 64
    assert _compile(tmp_path, "same") == (0, 1)  # first compile
    assert _compile(tmp_path, "same") == (1, 0)  # from the cache
    assert _compile(tmp_path, "changed") == (0, 1)  # another module changed: stale
