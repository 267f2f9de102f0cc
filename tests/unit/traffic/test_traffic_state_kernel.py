"""The WorldState read's compiled kernels against their numpy references: bit for bit where
IEEE 754 makes it so, within a few ULP where a transcendental function is involved."""

from __future__ import annotations

import numpy as np
import pytest
from ulp import assert_within_ulps

from hiyari.kinematics import point_ahead, wrap_angle
from hiyari.traffic.state_kernel import sumo_to_state, within

#: compiled kernels against numpy formulas: CI runs these again with numpy's dispatch limited
pytestmark = pytest.mark.kernels


def _reference(front, angle, speed, accel, vst, vrow, pst, prow, history, now, before, dt):
    """The read's numpy formulas: heading from SUMO's compass angle, the rectangle centre half
    a length behind the front bumper, persons' accelerations differenced over one step."""
    nv = len(vrow)
    st = np.concatenate([vst[vrow], pst[prow]])
    heading = wrap_angle(np.radians(90.0 - angle))
    xyz = front.copy()
    xyz[:, :2] = point_ahead(front[:, :2], heading, -0.5 * st[:, 1])
    hist = history[prow]
    fresh = hist[:, 0] != now
    hist[fresh, 2:] = hist[fresh, :2]
    hist[:, 0] = now
    hist[:, 1] = speed[nv:]
    history[prow] = hist
    accel = accel.copy()
    accel[nv:] = np.where(hist[:, 2] == before, (speed[nv:] - hist[:, 3]) / dt, 0.0)
    return xyz, heading, st, accel


def test_sumo_to_state_equals_numpy():
    rng = np.random.default_rng(5)
    nv, npers, k = 40, 30, 64
    n = nv + npers
    front = rng.uniform(-3000.0, 3000.0, (n, 3))
    angle = rng.uniform(-720.0, 720.0, n)
    angle[:4] = [0.0, 90.0, 180.0, 270.0]  # compass points: heading exactly on the axes
    speed = rng.uniform(0.0, 40.0, n)
    accel = np.where(np.arange(n) < nv, rng.normal(0.0, 2.0, n), np.nan)
    vst = np.column_stack([rng.integers(0, 5, k), rng.uniform(1, 18, (k, 3))])
    pst = np.column_stack([np.full(k, 5.0), rng.uniform(0.2, 2.0, (k, 3))])
    vrow = rng.permutation(k)[:nv].astype(np.intp)
    prow = rng.permutation(k)[:npers].astype(np.intp)
    history = np.full((k, 4), np.nan)
    dt = 0.1
    # three reads: first sight (no history), one step later, a second read at the same time
    reads = [(10.0, np.nan, 0.0), (10.1, 10.0, 0.3), (10.1, 10.0, 0.3)]
    h_ref = history.copy()
    base = speed
    for now, before, dv in reads:
        speed = base + dv
        want = _reference(front, angle, speed, accel, vst, vrow, pst, prow, h_ref, now, before, dt)
        got_accel = accel.copy()
        got = sumo_to_state(
            front, angle, speed, got_accel, vst, vrow, pst, prow, history, now, before, dt
        )
        xyz, heading, st, acc = (*got, got_accel)
        # heading through sin/cos/arctan2; the centre through cos/sin times half a length
        assert_within_ulps(heading, want[1], scale=np.pi)
        assert_within_ulps(xyz, want[0], scale=np.abs(front).max() + st[:, 1].max())
        assert np.array_equal(st, want[2]) and np.array_equal(acc, want[3])
        assert np.array_equal(history, h_ref, equal_nan=True)
    # persons seen a step ago: (v + 0.3 - v) / 0.1, by hand
    assert np.allclose(got_accel[nv:], 3.0)
    assert np.all(np.abs(got[1]) <= np.pi)


def test_within_equals_hypot_rule():
    rng = np.random.default_rng(6)
    xyz = rng.uniform(-100.0, 100.0, (500, 3))
    xyz[0, :2] = [13.0 + 30.0, 7.0]  # exactly on the circle
    got = within(xyz, 13.0, 7.0, 30.0)
    assert np.array_equal(got, np.hypot(xyz[:, 0] - 13.0, xyz[:, 1] - 7.0) <= 30.0)
    assert got[0] and 0 < got.sum() < 500
