"""kinematics' gap and extent functions are loops over kinematics_scalar's compiled kernels:
they broadcast like numpy, give each row the scalar kernel's value, and keep the shape."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from hiyari import kinematics as K
from hiyari import kinematics_scalar as S


def test_arrays_broadcast_and_equal_the_scalar_kernel_row_by_row() -> None:
    rng = np.random.default_rng(5)
    ca = rng.uniform(-6, 6, (3, 1, 2))  # against (4,) Bs: a (3, 4) table of pairs
    cb, hb = rng.uniform(-6, 6, (4, 2)), rng.uniform(-np.pi, np.pi, 4)
    ha = rng.uniform(-np.pi, np.pi, (3, 1))
    d = K.footprint_distance(ca, ha, 4.5, 1.8, cb, hb, 2.0, 0.8)
    assert d.shape == (3, 4) and d.dtype == np.float64
    for i in range(3):
        for j in range(4):
            one = S.footprint_distance(*ca[i, 0], ha[i, 0], 4.5, 1.8, *cb[j], hb[j], 2.0, 0.8)
            assert d[i, j] == one
    ex, ey = K.footprint_extent(np.array([4.0, 2.0]), 2.0, np.array([[0.0], [math.pi / 2]]))
    assert ex.shape == ey.shape == (2, 2)
    assert ex.tolist() == [[2.0, 1.0], [pytest.approx(1.0), pytest.approx(1.0)]]
    assert ey[1].tolist() == [pytest.approx(2.0), pytest.approx(1.0)]


def test_scalars_give_zero_dimensional_arrays_and_empty_stays_empty() -> None:
    o = np.zeros(2)
    d = K.footprint_distance(o, 0.0, 4.0, 2.0, np.array([10.0, 0.0]), 0.0, 4.0, 2.0)
    assert d.shape == () and d == 6.0
    assert K.box_distance(np.array([5.0, 3.0]), 2.0, 1.0).shape == ()
    # a point 3 m ahead of a north-facing 4 x 2 rectangle's front (its centre at the origin)
    assert K.rectangle_point_distance(o, math.pi / 2, 2.0, 1.0, np.array([0.0, 5.0])) == 3.0
    empty = np.zeros((0, 2))
    assert K.footprint_distance(empty, 0.0, 1.0, 1.0, empty, 0.0, 1.0, 1.0).shape == (0,)
    assert K.footprint_extent(np.zeros(0), 1.0, 0.0)[0].shape == (0,)


def test_nan_propagates_as_numpy_would() -> None:
    """A NaN coordinate gives NaN distances (max(NaN, 0) stays NaN, as np.maximum), not 0."""
    p = np.array([[np.nan, 0.0], [5.0, np.nan]])
    assert np.isnan(K.box_distance(p, 2.0, 1.0)).all()
    assert math.isnan(S.max0(math.nan)) and S.max0(-1.0) == 0.0


@pytest.mark.parametrize("shapes", [((1,), ()), ((3,), (), (3,)), ((1, 1), (1,))])
def test_the_kernels_get_no_broadcast_views(shapes) -> None:
    """Inputs reach the compiled loops as arrays of their own: numba types a broadcast view
    by its writeable flag, which warns on stderr on a fresh cache (a size-1 view is contiguous
    and was passed on), and numpy will make such views read-only."""
    _, flat = K._flat(*(np.zeros(s) for s in shapes))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for a in flat:
            a[...] = 1.0  # a broadcast view warns on write
