"""The C&C driver evaluator: cases worked on paper, the stepping reference, symmetry, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.errors import HiyariError
from hiyari.risk.cc.evaluator import evaluate_cut_in, evaluate_cut_out, evaluate_decel
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.reference_sim import simulate_cut_in, simulate_cut_out, simulate_decel

KMH = 1 / 3.6
A = 0.774 * 9.81  # 7.59294 m/s²
RAMP_LOSS = 0.06 * A  # distance lost to the 0.6 s ramp: (a / 0.6) 0.6³ / 6 = 0.45558 m


def braking_distance(v: float, v_end: float = 0.0) -> float:
    """Distance (relative to v_end) from braking onset until the speed is v_end: ramp then
    constant deceleration (valid when the ramp ends above v_end)."""
    dv = v - v_end
    return dv * 0.6 - RAMP_LOSS + (dv - 0.3 * A) ** 2 / (2 * A)


def test_deceleration_60kmh_1g_by_hand():
    """Lead and ego at 60 km/h (16.667 m/s), gap 2 s x 16.667 = 33.333 m. The lead brakes at
    1 g and stops after 16.667² / (2 x 9.81) = 14.158 m. The ego brakes from 0.4 + 0.75 =
    1.15 s: 19.167 m, then 16.667 x 0.6 - 0.456 = 9.544 m in the ramp and 14.389² / (2a) =
    13.634 m: 42.345 m. Final (= minimum) gap 33.333 + 14.158 - 42.345 = 5.147 m."""
    v = 60 * KMH
    expected = 2 * v + v * v / (2 * 9.81) - (1.15 * v + braking_distance(v))
    r = evaluate_decel(v, 1.0)
    assert expected == pytest.approx(5.147, abs=1e-3)
    assert r.min_gap_m[0] == pytest.approx(expected, abs=1e-9)
    assert not r.collision[0]
    assert r.t_brake_s[0] == pytest.approx(1.15)


def test_cut_out_60kmh_by_hand():
    """Ve0 = Vo0 = 60 km/h, Vy = 1 m/s: cut-out judged at 0.375 s, danger 0.775 s, braking at
    1.525 s. Stopping distance 16.667 x 1.525 + 9.544 + 13.634 = 48.595 m; the stopped car
    is 33.333 (THW 2 s) + 5.3 (lead length) + dx0_f ahead: the boundary is dx0_f = 9.962 m."""
    v = 60 * KMH
    boundary = 1.525 * v + braking_distance(v) - 2 * v - 5.3
    assert boundary == pytest.approx(9.962, abs=1e-3)
    r = evaluate_cut_out(v, 1.0, [boundary - 0.01, boundary + 0.01, 40.0])
    assert r.collision.tolist() == [True, False, False]
    assert r.min_gap_m[1] == pytest.approx(0.01, abs=1e-9)
    # the lead needs 1.9 m of lateral travel (1.9 s at 1 m/s = 31.7 m at 60 km/h) to clear
    assert r.valid.tolist() == [False, False, True]


def test_cut_in_by_hand():
    """Lane-aligned contact. Ve0 = 60, Vo0 = 30 km/h (closing 8.333 m/s), Vy = 1 m/s. Danger
    at 0.375 + 0.4 s, braking from 1.525 s, relative braking distance S = 8.333 x 0.6 - 0.456
    + 6.055² / (2a) = 6.959 m: the ego closes 8.333 x 1.525 + 6.959 = 19.667 m, so dx0 =
    19.667 m is the boundary. At dx0 = 60 m, TTC at danger is 6.4 s: not a critical cut-in
    (the default, the scenario ends); with "wait" the reaction waits for TTC = 2 s, and the
    gap at braking onset is (2 - 0.75) x 8.333 = 10.417 m, leaving 3.458 m."""
    ve, vo = 60 * KMH, 30 * KMH
    dv = ve - vo
    default = evaluate_cut_in(ve, vo, 60.0, 1.0, CCParams(contact="lane"))
    assert not default.collision[0] and np.isinf(default.t_brake_s[0])
    lane = CCParams(contact="lane", above_ttc="wait")
    relative = dv * 1.525 + braking_distance(ve, vo)
    assert relative == pytest.approx(19.667, abs=1e-3)
    r = evaluate_cut_in(ve, vo, [relative - 0.01, relative + 0.01, 60.0, 5.0], 1.0, lane)
    assert r.collision.tolist() == [True, False, False, True]
    assert r.min_gap_m[2] == pytest.approx(1.25 * dv - braking_distance(ve, vo), abs=1e-9)
    assert r.t_brake_s[2] == pytest.approx(60 / dv - 2 + 0.75)
    # dx0 = 5 m: at danger judgement (0.775 s) the gap is 5 - 8.333 x 0.775 = -1.458 m: the
    # other car is beside the ego, which does not brake for it (issue 15); at 1.6 s, when the
    # other enters the ego's width (1.6 m / 1 m/s), the ego is alongside (gap 5 - 8.333 x 1.6
    # = -8.333 m > -(4.8 + 5.3)): a side impact at 1.6 s at the full closing speed
    assert r.t_brake_s[3] == np.inf
    assert r.t_collision_s[3] == pytest.approx(1.6)
    assert r.impact_speed_mps[3] == pytest.approx(dv)


def test_position_based_judgement_agrees_at_1_8_mps():
    """Both danger judgements fall at 0.375 / 1.8 + 0.4 = 1.095 / 1.8 s when Vy = 1.8 m/s."""
    args = (70 * KMH, 40 * KMH, np.linspace(0, 40, 81), 1.8)
    a = evaluate_cut_in(*args)
    b = evaluate_cut_in(*args, params=CCParams(judgement="position"))
    assert np.allclose(a.min_gap_m, b.min_gap_m, atol=1e-9)
    slow = evaluate_cut_in(70 * KMH, 40 * KMH, 25.0, 1.0, CCParams(judgement="position"))
    assert slow.t_brake_s[0] == pytest.approx(1.095 + 0.75)


def test_cut_in_depends_on_relative_speed_only():
    """Symmetry with lane-aligned contact: shifting both speeds by the same amount changes
    nothing (the ego brakes down to the other's speed, so only the relative motion matters;
    with the Annex G heading the other car's yaw, atan2(Vy, Vo0), breaks it)."""
    rng = np.random.default_rng(3)
    n = 2000
    dv = rng.uniform(0, 60, n) * KMH
    vo = rng.uniform(15, 60, n) * KMH
    vy = rng.uniform(0.1, 3.0, n)
    dx0 = rng.uniform(0, 80, n)
    shift = rng.uniform(0, 50, n) * KMH
    for aeb in (False, True):
        p = CCParams(aeb=aeb, contact="lane")
        a = evaluate_cut_in(vo + dv, vo, dx0, vy, p)
        b = evaluate_cut_in(vo + dv + shift, vo + shift, dx0, vy, p)
        assert np.array_equal(a.collision, b.collision)
        assert np.allclose(a.min_gap_m, b.min_gap_m, atol=1e-9)


def test_aeb_only_helps():
    rng = np.random.default_rng(4)
    n = 3000
    vo = rng.uniform(10, 80, n) * KMH
    ve = vo + rng.uniform(0, 60, n) * KMH
    vy = np.minimum(rng.uniform(0.1, 3.0, n), vo)
    dx0 = rng.uniform(0, 80, n)
    plain = evaluate_cut_in(ve, vo, dx0, vy)
    aeb = evaluate_cut_in(ve, vo, dx0, vy, CCParams(aeb=True))
    assert not np.any(aeb.collision & ~plain.collision)
    assert aeb.collision.sum() < plain.collision.sum()
    assert np.all(aeb.t_brake_s <= plain.t_brake_s)


@pytest.mark.parametrize("aeb", [False, True])
def test_agrees_with_time_stepping(aeb):
    """The closed form against the independent 0.01 s stepping loop: same verdict wherever
    the margin exceeds what a 0.01 s step can move, and close minimum gaps / contact times
    (an event a step late moves the outcome by up to the closing speed x 0.01 s and more)."""
    p = CCParams(aeb=aeb)
    rng = np.random.default_rng(5)
    n = 40
    vo = rng.uniform(15, 90, n) * KMH
    ve = vo + rng.uniform(1, 50, n) * KMH
    vy = np.minimum(rng.uniform(0.3, 3.0, n), vo)
    dx0 = rng.uniform(0, 50, n)
    r = evaluate_cut_in(ve, vo, dx0, vy, p)
    for i in np.flatnonzero(r.t_brake_s < 50):  # within the stepping's 60 s horizon
        s = simulate_cut_in(ve[i], vo[i], dx0[i], vy[i], p)
        if abs(r.min_gap_m[i]) > 0.5 and r.min_gap_m[i] > -(4.8 + 5.3):
            assert s.collision == r.collision[i]
        if s.collision and r.collision[i]:
            assert s.t_collision_s == pytest.approx(r.t_collision_s[i], abs=0.05)
        elif not r.collision[i] and r.min_gap_m[i] >= 0:
            assert s.min_gap_m == pytest.approx(r.min_gap_m[i], abs=0.2)
    v = rng.uniform(10, 130, n) * KMH
    vy = np.minimum(rng.uniform(0.3, 3.0, n), v)
    dx0_f = rng.uniform(1, 80, n)
    gx = rng.uniform(0.05, 1.0, n)
    gap = rng.uniform(0.2, 1.0, n) * 2 * v
    co = evaluate_cut_out(v, vy, dx0_f, p)
    de = evaluate_decel(v, gx, p, dx0_m=gap)
    for i in range(n):
        s = simulate_cut_out(v[i], vy[i], dx0_f[i], p)
        if abs(co.min_gap_m[i]) > 0.5:
            assert s.collision == co.collision[i]
        if not s.collision and not co.collision[i]:
            assert s.min_gap_m == pytest.approx(co.min_gap_m[i], abs=0.5)
        s = simulate_decel(v[i], gx[i], p, dx0=gap[i])
        if abs(de.min_gap_m[i]) > 0.3:
            assert s.collision == de.collision[i]
        if not s.collision and not de.collision[i]:
            assert s.min_gap_m == pytest.approx(de.min_gap_m[i], abs=0.3)


def _safe_stays_safe(collision: np.ndarray) -> bool:
    """Along increasing gaps: after the first collision, once safe, always safe."""
    hit = np.flatnonzero(collision)
    if hit.size == 0:
        return True
    safe = np.flatnonzero(~collision[hit[0] :])
    return safe.size == 0 or not collision[hit[0] + safe[0] :].any()


def test_larger_gap_never_turns_safe_into_collision():
    """Monotonicity over dx0 on a dense grid. Below the colliding gaps lies only the case of
    an ego that has fully passed the other before it enters the lane (it then cuts in
    behind): that is the one 'no collision' a larger gap may turn into a collision. Above
    the first colliding gap, no collision once avoided ever comes back."""
    rng = np.random.default_rng(6)
    gaps = np.arange(0, 150, 0.25)
    for aeb in (False, True):
        p = CCParams(aeb=aeb)
        for _ in range(60):
            vo = rng.uniform(10, 90) * KMH
            ve = vo + rng.uniform(1, 60) * KMH
            vy = min(rng.uniform(0.1, 3.0), vo)
            r = evaluate_cut_in(ve, vo, gaps, vy, p)
            assert _safe_stays_safe(r.collision)
            # the gaps below the colliding ones are pass-throughs, with min gap <= -(4.8 + 5.3)
            hit = np.flatnonzero(r.collision)
            if hit.size:
                assert np.all(r.min_gap_m[: hit[0]] <= -(4.8 + 5.3) + 1e-9)
        for ve in np.array([20, 60, 100, 130]) * KMH:
            for gx in (0.3, 0.7, 1.0):
                d = evaluate_decel(ve, gx, p, dx0_m=gaps)
                assert _safe_stays_safe(d.collision) and not d.collision[-1]
            c = evaluate_cut_out(ve, 1.0, gaps[1:], p)
            assert _safe_stays_safe(c.collision) and not c.collision[-1]


@pytest.mark.parametrize(
    ("call", "needle"),
    [
        (lambda: evaluate_cut_in(-1.0, 0.0, 10.0, 1.0), "ve0_mps"),
        (lambda: evaluate_cut_in(20.0, 10.0, 10.0, 0.0), "vy_mps"),
        (lambda: evaluate_cut_in(20.0, 10.0, 10.0, -1.0), "vy_mps"),
        (lambda: evaluate_cut_in(20.0, 25.0, 10.0, 1.0), "faster than the ego"),
        (lambda: evaluate_cut_in(20.0, 2.78, 10.0, 3.0), "physically impossible"),
        (lambda: evaluate_cut_in(20.0, 10.0, -3.0, 1.0), "dx0_m"),
        (lambda: evaluate_cut_in(20.0, 10.0, np.nan, 1.0), "not finite"),
        (lambda: evaluate_cut_in([20.0, 30.0], [10.0, 5.0, 1.0], 5.0, 1.0), "shapes"),
        (lambda: evaluate_cut_out(0.0, 1.0, 10.0), "ve0_mps"),
        (lambda: evaluate_cut_out(20.0, 1.0, 0.0), "dx0_f_m"),
        (lambda: evaluate_decel(20.0, 1.2), "road friction"),
        (lambda: evaluate_decel(20.0, 0.0), "gx_max_g"),
        (lambda: CCParams(max_decel_g=-0.5), "max_decel_g"),
        (lambda: CCParams(judgement="guess"), "judgement"),
        (lambda: CCParams(ego_width_m=5.2), "overlap"),
    ],
)
def test_bad_input_refused(call, needle):
    with pytest.raises(HiyariError, match=needle):
        call()


def test_param_overrides():
    p = CCParams().with_overrides(["max_decel_g=0.7", "aeb=true", "judgement=position"])
    assert (p.max_decel_g, p.aeb, p.judgement) == (0.7, True, "position")
    with pytest.raises(HiyariError, match="not a number"):
        CCParams().with_overrides(["thw_s=two"])
    with pytest.raises(HiyariError, match="NAME=VALUE"):
        CCParams().with_overrides(["nonsense"])
    assert CCParams.from_dict(p.as_dict()) == p
