"""Results across CPUs: numpy's SIMD dispatch limited to the baseline stands in for another CPU.

The README's promise: on one machine and install, bit for bit; across CPUs, the same verdicts
and figures within 1e-9 (m, s). numpy's vectorised sin/cos/arctan2/exp on AVX-512 differ from
its baseline paths (and from the libm that the compiled kernels call) in the last bits.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import pytest
from paths import REPO_ROOT

#: every dispatch target numpy's x86-64 wheels build above the baseline
BASELINE_ONLY = "X86_V3 X86_V4 AVX512_ICL AVX512_SPR AVX512_SKX AVX512F AVX2 FMA3"
PROBE = REPO_ROOT / "tests" / "support" / "dispatch_probe.py"


def _start_probe(limit_dispatch: bool) -> subprocess.Popen:
    env = dict(os.environ)
    env.pop("NPY_DISABLE_CPU_FEATURES", None)
    if limit_dispatch:
        env["NPY_DISABLE_CPU_FEATURES"] = BASELINE_ONLY
    return subprocess.Popen(
        [sys.executable, str(PROBE)], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )


def _result(probe: subprocess.Popen) -> dict:
    out, err = probe.communicate(timeout=600)
    assert probe.returncode == 0, err.decode()[-2000:]
    return json.loads(out)


def _close(a: float, b: float, tol: float) -> bool:
    return a == b or (math.isfinite(a) and math.isfinite(b) and abs(a - b) <= tol)


@pytest.mark.timeout(900)
def test_verdicts_equal_and_figures_within_1e9_with_numpy_dispatch_limited():
    runs = _start_probe(False), _start_probe(True)  # side by side: two processes, two cores
    default, limited = (_result(p) for p in runs)
    assert default.keys() == limited.keys() and len(default) == 3
    for name, want in default.items():
        got = limited[name]
        assert got["verdict"] == want["verdict"], name
        assert _close(got["min_ttc"], want["min_ttc"], 1e-9), name
        assert len(got["positions"]) == len(want["positions"]) > 50, name
        for g, w in zip(got["positions"], want["positions"], strict=True):
            assert len(g) == len(w), name
            assert all(abs(x - y) <= 1e-9 for x, y in zip(g, w, strict=True)), name
        for key in ("ttc", "gap"):  # s, m
            assert all(_close(x, y, 1e-9) for x, y in zip(got[key], want[key], strict=True))
