"""Issue 15 item 1: a C&C driver does not brake for a cut-in car that is already beside it.

When the danger judgement finds the longitudinal gap at or below 0, the TTC rule (gap <
2 s x closing speed) would hold for any negative gap; braking then keeps the ego alongside
the car that is moving into its lane, turning a pass into a side collision.
"""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.risk.cc.evaluator import evaluate_cut_in
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.reference_sim import simulate_cut_in

KMH = 1 / 3.6


def test_no_braking_into_a_car_alongside_by_hand():
    """Ve0 = 60, Vo0 = 42 km/h (closing 5 m/s), Vy = 0.3 m/s, dx0 = 6 m. Danger judgement
    at 0.375 / 0.3 + 0.4 = 1.65 s, when the gap is 6 - 5 x 1.65 = -2.25 m: the car is beside
    the ego. Braking then (from 2.4 s, relative braking distance 5 x 0.6 - 0.456 + (5 -
    2.278)² / (2 x 7.593) = 3.032 m) would leave the ego 6 - 12 - 3.032 = -9.03 m, less than
    the 10.1 m of both lengths: still alongside when the car enters the ego lane (after about
    5 s at 0.3 m/s), a side collision. Not braking, the ego is 6 - 5 x 5 = -19 m by then:
    fully past, no collision."""
    ve, vo, dx0, vy = 60 * KMH, 42 * KMH, 6.0, 0.3
    r = evaluate_cut_in(ve, vo, dx0, vy)
    assert not r.collision[0]
    assert r.t_brake_s[0] == np.inf
    s = simulate_cut_in(ve, vo, dx0, vy, CCParams())
    assert not s.collision
    # just ahead at danger judgement (gap +0.25 m) it does brake, and cannot pass
    ahead = evaluate_cut_in(ve, vo, 8.5, vy)
    assert ahead.t_brake_s[0] == pytest.approx(1.65 + 0.75)
    assert ahead.collision[0]


def test_never_brakes_when_beside_at_danger_judgement():
    """Whatever the speeds: a gap <= 0 at danger judgement means no braking at all, in the
    closed form and in the stepping reference."""
    rng = np.random.default_rng(21)
    n = 4000
    vo = rng.uniform(10, 120, n) * KMH
    ve = vo + rng.uniform(1, 60, n) * KMH
    vy = np.minimum(rng.uniform(0.1, 3.0, n), vo)
    t_danger = 0.375 / vy + 0.4
    dx0 = rng.uniform(0, 1, n) * (ve - vo) * t_danger  # beside the ego at danger judgement
    r = evaluate_cut_in(ve, vo, dx0, vy)
    assert np.all(np.isinf(r.t_brake_s))


def test_alongside_region_agrees_with_stepping():
    """The closed form and the 0.01 s stepping loop over the affected region (Vy <= 0.45 m/s,
    gaps around the one at which the car is beside the ego at danger judgement): the same
    verdict wherever a 0.01 s step cannot flip it, and some of those are passes that braking
    would have turned into side collisions."""
    rng = np.random.default_rng(22)
    n = 60
    vo = rng.uniform(15, 80, n) * KMH
    ve = vo + rng.uniform(5, 40, n) * KMH
    vy = rng.uniform(0.1, 0.45, n)
    dv = ve - vo
    dx0 = np.maximum(dv * (0.375 / vy + 0.4) + rng.uniform(-8, 4, n), 0.0)
    for params in (CCParams(), CCParams(contact="lane"), CCParams(aeb=True)):
        r = evaluate_cut_in(ve, vo, dx0, vy, params)
        # verdicts a 0.01 s step could flip: those that change within 0.3 m of the gap
        near = np.zeros(n, bool)
        for shift in (-0.3, 0.3):
            moved = evaluate_cut_in(ve, vo, np.maximum(dx0 + shift, 0.0), vy, params)
            near |= moved.collision != r.collision
        passes_unbraked = 0
        for i in range(n):
            s = simulate_cut_in(ve[i], vo[i], dx0[i], vy[i], params)
            if not near[i]:
                assert s.collision == r.collision[i], (ve[i], vo[i], dx0[i], vy[i])
            passes_unbraked += bool(np.isinf(r.t_brake_s[i]) and not r.collision[i])
        assert passes_unbraked >= 5
