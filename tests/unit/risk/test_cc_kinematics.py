"""Closed-form piecewise kinematics against motions worked on paper."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.risk.cc.kinematics import (
    Motion,
    PiecewiseCubic,
    max_of_profiles,
    profile_value,
    ramp_knots,
)

G = 9.81
A_MAX = 0.774 * G  # 7.59294 m/s²


def test_braking_to_standstill_matches_hand_computation():
    """20 m/s, braking force from t = 1 s, linear ramp to 0.774 g over 0.6 s, held to a stop.

    On paper (a = 7.59294 m/s², jerk a / 0.6): 20 m before the ramp; during the ramp v drops
    by a·0.6/2 = 2.27788 m/s and the car covers 20·0.6 - (a/0.6)·0.6³/6 = 12 - 0.45558 =
    11.54442 m; then 17.72212² / (2a) = 20.68194 m at constant a, taking 17.72212 / a =
    2.33403 s. Stop at t = 3.93403 s after 52.22636 m.
    """
    t, d = ramp_knots(np.array([1.0]), 0.6, A_MAX)
    ego = Motion.braking(np.array([20.0]), t, d, np.array([0.0]))
    x, v, a, _ = ego.state_at(np.array([[0.5, 1.6, 3.93403, 10.0]]))
    assert x[0, 0] == pytest.approx(10.0)
    assert v[0, 1] == pytest.approx(20 - A_MAX * 0.3)
    assert x[0, 1] == pytest.approx(20 + 11.54442, abs=1e-5)
    assert x[0, 3] == pytest.approx(52.22636, abs=1e-5)
    assert v[0, 3] == 0 and a[0, 3] == 0
    assert v[0, 2] == pytest.approx(0.0, abs=1e-4)


def test_braking_stops_at_target_speed_inside_the_ramp():
    """From 10 m/s to 9.5 m/s: the ramp's speed loss j t²/2 reaches 0.5 m/s at
    t = sqrt(2·0.5·0.6/a) = 0.28111 s after onset, well inside the 0.6 s ramp."""
    t, d = ramp_knots(np.array([0.0]), 0.6, A_MAX)
    ego = Motion.braking(np.array([10.0]), t, d, np.array([9.5]))
    t_stop = np.sqrt(2 * 0.5 * 0.6 / A_MAX)
    x, v, _, _ = ego.state_at(np.array([[t_stop, t_stop + 5.0]]))
    assert v[0, 0] == pytest.approx(9.5, abs=1e-9)
    assert v[0, 1] == pytest.approx(9.5, abs=1e-12)
    assert x[0, 1] - x[0, 0] == pytest.approx(5 * 9.5)


def test_no_braking_when_never_started_or_already_slow():
    t, d = ramp_knots(np.array([np.inf, 1.0]), 0.6, A_MAX)
    ego = Motion.braking(np.array([15.0, 5.0]), t, d, np.array([0.0, 8.0]))
    x, v, _, _ = ego.state_at(np.array([20.0, 20.0]))
    assert x.tolist() == [300.0, 100.0]
    assert v.tolist() == [15.0, 5.0]


def test_step_deceleration():
    """30 m/s braking at 1 g: stops after 3.0581 s and 45.8716 m."""
    lead = Motion.step_deceleration(np.array([30.0]), np.array([G]))
    x, v, a, _ = lead.state_at(np.array([[1.0, 100.0]]))
    assert x[0, 0] == pytest.approx(30 - G / 2)
    assert v[0, 0] == pytest.approx(30 - G)
    assert a[0, 0] == pytest.approx(-G)
    assert x[0, 1] == pytest.approx(900 / (2 * G))


def test_gap_minimum_and_first_crossing():
    """Ego at 20 m/s braking at a constant 5 m/s² from t = 0 behind a car at 10 m/s, 8 m
    ahead: gap = 8 - 10 t + 2.5 t², minimum -2 at t = 2 s, zero at t = 2 - sqrt(0.8) s."""
    ego = Motion.braking(
        np.array([20.0]), np.array([[0.0, 0.0]]), np.array([[5.0, 5.0]]), np.array([10.0])
    )
    gap = PiecewiseCubic.gap(np.array([8.0]), Motion.constant_speed(np.array([10.0])), ego)
    assert gap.minimum_after(np.array([0.0]))[0] == pytest.approx(-2.0)
    assert gap.first_negative(np.array([0.0]))[0] == pytest.approx(2 - np.sqrt(0.8), abs=1e-12)
    # from t = 2.5 s the gap stays at its final -2 m
    assert gap.minimum_after(np.array([2.5]))[0] == pytest.approx(-2.0)
    assert gap.first_negative(np.array([2.5]))[0] == 2.5
    # gap + 2 s x d(gap)/dt = -12 + 2.5 t²: negative from t = 0 (TTC 0.8 s < 2 s) ...
    assert gap.plus_derivative(2.0).first_negative(np.array([0.0]))[0] == 0.0
    # ... and gap + 0.5 d(gap)/dt = 3 - 7.5 t + 2.5 t² first reaches 0 at t = (7.5 - sqrt(26.25)) / 5
    t_ttc = gap.plus_derivative(0.5).first_negative(np.array([0.0]))[0]
    assert t_ttc == pytest.approx((7.5 - np.sqrt(26.25)) / 5, abs=1e-12)


def test_cubic_root_in_the_ramp():
    """Gap during a ramp is a cubic: 2 - 2 t + (j/6) t³ with j = 12 m/s³ (2 m/s closing,
    ramp from 0 to 7.2 m/s² over 0.6 s, ego stops closing when 2 = j t²/2, t = 0.57735 s).
    The gap is 2 - 2t + 2t³: it bottoms out at t = 1/sqrt(3) with 2 - 0.7698 = 1.2302 m."""
    ego = Motion.braking(
        np.array([12.0]), np.array([[0.0, 0.6]]), np.array([[0.0, 7.2]]), np.array([10.0])
    )
    gap = PiecewiseCubic.gap(np.array([2.0]), Motion.constant_speed(np.array([10.0])), ego)
    t_min = 1 / np.sqrt(3)
    assert gap.minimum_after(np.array([0.0]))[0] == pytest.approx(2 - 2 * t_min + 2 * t_min**3)
    # shifted down by 1.5 m it crosses zero where 0.5 - 2t + 2t³ = 0 on the way down
    t_root = gap.shifted(-1.5).first_negative(np.array([0.0]))[0]
    assert 0.5 - 2 * t_root + 2 * t_root**3 == pytest.approx(0.0, abs=1e-12)
    assert 0 < t_root < t_min


def test_max_of_two_ramps():
    """Driver ramp 1.0 → 1.6 s to 7.593 m/s², AEB ramp 1.2 → 1.8 s to 8.339 m/s². The AEB
    (13.897 m/s³) overtakes the held driver level at 1.2 + 7.593 / 13.897 = 1.7464 s."""
    t1, d1 = ramp_knots(np.array([1.0]), 0.6, A_MAX)
    t2, d2 = ramp_knots(np.array([1.2]), 0.6, 0.85 * G)
    kt, kd = max_of_profiles(t1, d1, t2, d2)
    cross = 1.2 + A_MAX / (0.85 * G / 0.6)
    assert np.any(np.isclose(kt[0], cross))
    tq = np.linspace(0, 3, 301)[None, :]
    expected = np.maximum(profile_value(t1, d1, tq), profile_value(t2, d2, tq))
    assert np.allclose(profile_value(kt, kd, tq), expected, atol=1e-12)
