"""Comparing compiled kernels with numpy formulas that go through transcendental functions.

numba calls the platform libm for sin, cos, arctan2, exp and pow; numpy dispatches to its own
SIMD versions on CPUs that have them (AVX-512 among others), which may differ in the last
bits. Exact equality is kept where IEEE 754 guarantees it (+, -, *, /, sqrt, no contraction);
results that went through a transcendental function are compared in units in the last place.
"""

from __future__ import annotations

import numpy as np

#: bound for one transcendental call and the few roundings after it
TRANSCENDENTAL_ULPS = 4


def assert_within_ulps(
    got: np.ndarray,
    want: np.ndarray,
    ulps: float = TRANSCENDENTAL_ULPS,
    scale: float | np.ndarray = 0.0,
) -> None:
    """Assert ``|got - want| <= ulps * spacing(max(|want|, scale))`` element by element, with NaN
    in the same places and infinities equal. ``scale``: the magnitude of the terms that were
    summed into the result (for results that cancel to near zero), in the result's units."""
    got, want = np.asarray(got, float), np.asarray(want, float)
    assert got.shape == want.shape
    nan = np.isnan(want)
    assert np.array_equal(np.isnan(got), nan), "NaN in different places"
    finite = np.isfinite(want)
    assert np.array_equal(got[~finite & ~nan], want[~finite & ~nan]), "infinities differ"
    unit = np.spacing(np.maximum(np.abs(want), scale))
    # only finite places are compared here: inf - inf would warn (and mean nothing)
    err = np.abs(np.where(finite, got, 0.0) - np.where(finite, want, 0.0))
    bad = finite & ~(err <= ulps * unit)
    assert not bad.any(), (
        f"{int(bad.sum())} values beyond {ulps} ULP, worst {float(np.max(err[bad] / unit[bad])):.1f}"
    )
