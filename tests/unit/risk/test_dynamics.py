"""Vehicle-motion disturbances: grip use against hand-computed v^2 / R and mu g (JAMA 4.3)."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.bridge.studies.grip.road import MotionDisturbance, expressway_profile
from hiyari.errors import HiyariError
from hiyari.net.sumo.build import ExpresswayParams
from hiyari.risk.dynamics.grip import band, quasi_static_grip_use
from hiyari.risk.dynamics.vehicle import VehicleParams, crosswind_force, simulate
from hiyari.units import G

# a flat (no cross slope) 200 m curve: v^2 / R alone loads the tyres
CURVE = ExpresswayParams(
    length=900.0,
    curve_radius=200.0,
    curve_start=300.0,
    curve_length=300.0,
    transition_length=60.0,
    cross_slope=0.0,
    superelevation=0.0,
    on_ramp=False,
    off_ramp=False,
)
V = 100 / 3.6


def test_jama_worked_example_eq4():
    # JAMA 4.3.3.4: V = 100 km/h, R = 463 m, i = 6 % -> f = V^2 / (127 R) - i = 0.11 g
    eps = quasi_static_grip_use(V, 1 / 463.0, mu=1.0, cross_slope=0.06)
    assert eps == pytest.approx(100**2 / (127 * 463) - 0.06, abs=2e-3)


def test_mu_03_exceeds_full_grip_where_mu_1_is_fine():
    ay = V**2 / 200.0  # 3.858 m/s^2
    assert ay < 1.0 * G and ay > 0.3 * G  # hand check: fine at mu 1, beyond at mu 0.3
    dry = simulate(expressway_profile(CURVE, MotionDisturbance(mu=1.0)), V)
    arc = (dry.s > 430) & (dry.s < 590)
    assert np.median(dry.grip_use[arc]) == pytest.approx(ay / (1.0 * G), rel=0.03)
    assert dry.grip_use.max() < 0.5 and dry.departed_at is None
    assert np.median(np.abs(dry.ay[arc])) == pytest.approx(ay, rel=0.03)
    wet = simulate(expressway_profile(CURVE, MotionDisturbance(mu=0.3)), V)
    assert wet.grip_use.max() > 1.0
    assert wet.departed_at is not None and 360 < wet.departed_at < 700


def test_bands_and_crosswind():
    assert list(band([0.1, 0.3, 0.5, 0.75, 0.9, 1.2])) == [0, 0, 1, 1, 2, 3]
    p = VehicleParams()
    # beta = atan(10 / 27.78); F = 0.5 rho (v^2 + w^2) A c beta
    beta = np.arctan2(10.0, V)
    assert float(crosswind_force(p, V, 10.0)) == pytest.approx(
        0.5 * 1.2 * (V**2 + 100) * 2.2 * 2.5 * beta
    )
    with pytest.raises(HiyariError, match="mu"):
        MotionDisturbance(mu=0.0)
