"""Annex G trajectories for scripting SUMO: the definition's properties and consistency with
the evaluator."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hiyari.errors import HiyariError
from hiyari.risk.cc.evaluator import evaluate_cut_in, evaluate_cut_out, evaluate_decel
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.trajectory import cut_in_tracks, cut_out_tracks, decel_tracks

KMH = 1 / 3.6
T = np.arange(0, 15, 0.01)


def test_cut_in_other_vehicle_follows_annex_g():
    """Lateral velocity a step to Vy at t = 0, longitudinal speed held at Vo0, heading along
    the velocity, lateral motion ends centred in the ego lane (3.5 m / 1.5 m/s = 2.333 s)."""
    tracks = cut_in_tracks(80 * KMH, 50 * KMH, 25.0, 1.5, T)
    other = tracks["other"]
    assert other.y_m[0] == 3.5 and other.vy_mps[0] == -1.5
    assert np.allclose(other.vx_mps, 50 * KMH)
    moving = T < 3.5 / 1.5
    assert np.allclose(other.vy_mps[moving], -1.5) and np.all(other.vy_mps[~moving] == 0)
    assert np.all(other.y_m[~moving] == 0)
    assert np.allclose(other.heading_rad[moving], np.arctan2(-1.5, 50 * KMH))
    assert np.all(other.heading_rad[~moving] == 0)
    assert other.x_front_m[0] == pytest.approx(25.0 + 5.3)
    assert np.allclose(np.diff(other.x_front_m), 50 * KMH * 0.01)


def test_tracks_reproduce_the_evaluated_gap():
    """Other vehicle rear - C&C ego front, sampled, matches the evaluator's minimum gap (the
    cut-in under the 'wait' convention: the C&C driver reacts when TTC falls to 2 s, so the
    tracks hold the whole braking; under the default 'end' this cut-in is not critical)."""
    ve, vo, dx0, vy = 80 * KMH, 50 * KMH, 25.0, 1.5
    wait = replace(CCParams(), above_ttc="wait")
    tracks = cut_in_tracks(ve, vo, dx0, vy, T, wait)
    gap = tracks["other"].x_front_m - 5.3 - tracks["cc_ego"].x_front_m
    r = evaluate_cut_in(ve, vo, dx0, vy, wait)
    assert gap.min() == pytest.approx(r.min_gap_m[0], abs=1e-6)
    ego = tracks["cc_ego"]
    assert ego.vx_mps[0] == ve and ego.vx_mps[-1] == pytest.approx(vo)
    assert ego.ax_mps2.min() == pytest.approx(-0.774 * 9.81)

    co = cut_out_tracks(70 * KMH, 1.0, 45.0, T)
    gap = co["stopped"].x_front_m - 5.3 - co["cc_ego"].x_front_m
    assert gap.min() == pytest.approx(evaluate_cut_out(70 * KMH, 1.0, 45.0).min_gap_m[0], abs=1e-6)
    assert co["lead"].y_m[-1] == 3.5 and co["stopped"].vx_mps.max() == 0

    de = decel_tracks(100 * KMH, 0.8, T)
    gap = de["lead"].x_front_m - 5.3 - de["cc_ego"].x_front_m
    assert gap.min() == pytest.approx(evaluate_decel(100 * KMH, 0.8).min_gap_m[0], abs=1e-3)
    assert de["lead"].ax_mps2[0] == pytest.approx(-0.8 * 9.81)
    assert de["lead"].vx_mps[-1] == 0


def test_mirror_symmetry():
    """A cut-in from the right lane is the mirror image of one from the left."""
    left = cut_in_tracks(60 * KMH, 40 * KMH, 10.0, 2.0, T)["other"]
    right = cut_in_tracks(60 * KMH, 40 * KMH, 10.0, 2.0, T, side=-1)["other"]
    assert np.array_equal(left.y_m, -right.y_m)
    assert np.array_equal(left.heading_rad, -right.heading_rad)
    assert np.array_equal(left.x_front_m, right.x_front_m)
    with pytest.raises(HiyariError, match="side"):
        cut_in_tracks(60 * KMH, 40 * KMH, 10.0, 2.0, T, side=2)
    with pytest.raises(HiyariError, match="t_s"):
        decel_tracks(60 * KMH, 0.5, [-1.0, 0.0])
