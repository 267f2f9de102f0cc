"""Issue 15 item 3: the driver-model conventions the R157 text leaves open, as named options
(API and CLI), each worked by hand, equal in the closed form and the stepping reference, and
named on every datasheet; the defaults are docs/models.md's."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from hiyari.bridge.cli.main import main
from hiyari.bridge.studies.report.datasheets import cut_in_figure, cut_out_figure, decel_figure
from hiyari.risk.cc.boundary import Grid, cut_in_datasheet, cut_out_datasheet, decel_datasheet
from hiyari.risk.cc.evaluator import evaluate_cut_in, evaluate_cut_out, evaluate_decel
from hiyari.risk.cc.model import CONVENTIONS, CCParams
from hiyari.risk.cc.reference_sim import simulate_cut_in, simulate_cut_out, simulate_decel
from hiyari.risk.cc.regions import cut_in_regions

KMH = 1 / 3.6
A = 0.774 * 9.81


def _relative_braking_distance(dv: float) -> float:
    """Distance (m) closed while braking from closing speed ``dv`` to 0 (0.6 s ramp to A)."""
    return dv * 0.6 - A * 0.6**2 / 6 + (dv - 0.5 * A * 0.6) ** 2 / (2 * A)


def test_defaults_are_models_md():
    """docs/models.md §1: danger 0.4 s after the wander-zone exit; a cut-in whose TTC at
    danger judgement is >= 2 s is not critical (the scenario ends); the perception delay
    applies in the cut-out and the deceleration; contact on the rectangles at the Annex G
    heading (heading along the velocity)."""
    p = CCParams()
    assert p.conventions() == {name: allowed[0] for name, allowed in CONVENTIONS.items()}
    assert (p.judgement, p.above_ttc, p.cut_out_perception) == ("time", "end", True)
    assert (p.decel_perception, p.contact) == ("always", "heading")
    assert p.is_models_default() and "not the docs/models.md" not in p.convention_note()
    assert "not the docs/models.md default" in CCParams(above_ttc="wait").convention_note()


def test_danger_at_first_overlap_by_hand():
    """Lane-aligned, Ve0 = 60, Vo0 = 30 km/h (8.333 m/s closing), Vy = 1 m/s: the other
    enters the ego's width at 1.6 / 1 = 1.6 s, braking from 2.35 s; the ego closes 8.333 x
    2.35 + 6.959 = 26.54 m: the boundary (time-based: 19.667 m)."""
    dv = 30 * KMH
    p = CCParams(judgement="overlap", contact="lane")
    boundary = dv * 2.35 + _relative_braking_distance(dv)
    assert boundary == pytest.approx(26.543, abs=1e-3)
    r = evaluate_cut_in(60 * KMH, 30 * KMH, [boundary - 0.01, boundary + 0.01], 1.0, p)
    assert r.collision.tolist() == [True, False]
    assert r.t_brake_s[1] == pytest.approx(2.35)
    upper = cut_in_regions(np.array([60 * KMH]), np.array([30 * KMH]), np.array([1.0]), p).upper
    assert upper[0] == pytest.approx(boundary, abs=1e-5)  # less contact_tol_m


def test_scenario_ends_when_ttc_is_above_the_threshold_by_hand():
    """Ve0 = 100, Vo0 = 45 km/h (15.278 m/s closing), Vy = 1 m/s, danger at 0.775 s. With
    "wait" the TTC-2 s reaction comes too late at every large gap (no Preventable gap above
    the colliding ones); with "end" a cut-in whose TTC at danger is >= 2 s is not critical,
    so the boundary is the gap at which TTC at danger is exactly 2 s: 15.278 x 2.775 =
    42.396 m (a reaction at 0.775 s would need 15.278 x 1.525 + 19.842 = 43.14 m)."""
    ve, vo, vy = np.array([100 * KMH]), np.array([45 * KMH]), np.array([1.0])
    dv = float(ve[0] - vo[0])
    wait = cut_in_regions(ve, vo, vy, CCParams(above_ttc="wait"))
    end = cut_in_regions(ve, vo, vy, CCParams())  # the default
    assert np.isinf(wait.upper[0])
    assert dv * 1.525 + _relative_braking_distance(dv) == pytest.approx(43.14, abs=5e-3)
    assert end.upper[0] == pytest.approx(dv * 2.775, abs=1e-6)
    r = evaluate_cut_in(ve, vo, 60.0, vy, CCParams())
    assert not r.collision[0] and np.isinf(r.t_brake_s[0])
    r = evaluate_cut_in(ve, vo, 60.0, vy, CCParams(above_ttc="wait"))
    assert r.collision[0] and r.t_brake_s[0] == pytest.approx(60 / dv - 2 + 0.75)


def test_cut_out_without_perception_delay_by_hand():
    """Ve0 = 60 km/h, Vy = 1 m/s: braking at 0.375 + 0.75 s instead of 1.525 s, so the
    boundary drops by 16.667 x 0.4 = 6.667 m, from 9.962 m to 3.295 m."""
    v = 60 * KMH
    boundary = 1.125 * v + _relative_braking_distance(v) - 2 * v - 5.3
    assert boundary == pytest.approx(3.295, abs=1e-3)
    p = CCParams(cut_out_perception=False)
    r = evaluate_cut_out(v, 1.0, [boundary - 0.01, boundary + 0.01], p)
    assert r.collision.tolist() == [True, False]
    assert r.t_brake_s[0] == pytest.approx(1.125)
    sheet = cut_out_datasheet(Grid(60, 60, 1), Grid(1, 1, 1), p, resolution_m=None)
    assert sheet.boundary_dx0_f_m[0] == pytest.approx(boundary, abs=1e-9)


def test_deceleration_perception_conventions_by_hand():
    """Braking onset after the lead's: 0.4 + 0.75 s ("always"), 0.75 s ("never"); with
    "hard-braking" the 0.4 s only above 5 m/s² (0.4 g = 3.92 m/s²: none; 0.8 g: with)."""
    v = np.full(2, 100 * KMH)
    gx = np.array([0.4, 0.8])
    onset = {
        "always": [1.15, 1.15],
        "never": [0.75, 0.75],
        "hard-braking": [0.75, 1.15],
    }
    for name, want in onset.items():
        r = evaluate_decel(v, gx, CCParams(decel_perception=name))
        assert r.t_brake_s.tolist() == pytest.approx(want)
    # at 100 km/h, 1 g, THW 2 s the 0.4 s decide the case: 0.4 x 27.8 = 11.1 m of gap
    hard = [evaluate_decel(100 * KMH, 1.0, CCParams(decel_perception=n)) for n in onset]
    assert hard[1].min_gap_m[0] - hard[0].min_gap_m[0] == pytest.approx(0.4 * 100 * KMH)


@pytest.mark.parametrize(
    "params",
    [
        CCParams(judgement="overlap"),
        CCParams(judgement="position", above_ttc="end"),
        CCParams(cut_out_perception=False, decel_perception="never"),
        CCParams(decel_perception="hard-braking", contact="lane"),
    ],
    ids=["overlap", "position-end", "no-delay", "hard-braking"],
)
def test_conventions_agree_with_stepping(params):
    """Every convention is implemented twice, in the closed form and the 0.01 s stepping
    loop: the verdicts agree wherever a 0.01 s step cannot flip them."""
    rng = np.random.default_rng(41)
    n = 24
    vo = rng.uniform(20, 90, n) * KMH
    ve = vo + rng.uniform(2, 50, n) * KMH
    vy = np.minimum(rng.uniform(0.2, 3.0, n), vo)
    dx0 = rng.uniform(0, 45, n)
    r = evaluate_cut_in(ve, vo, dx0, vy, params)
    near = np.zeros(n, bool)
    for shift in (-0.3, 0.3):
        near |= evaluate_cut_in(ve, vo, np.maximum(dx0 + shift, 0), vy, params).collision != (
            r.collision
        )
    checked = 0
    for i in np.flatnonzero(~near):
        assert simulate_cut_in(ve[i], vo[i], dx0[i], vy[i], params).collision == r.collision[i]
        checked += 1
    assert checked > n // 2
    v = rng.uniform(20, 130, 8) * KMH
    gx = rng.uniform(0.2, 1.0, 8)
    dx0_f = rng.uniform(1, 60, 8)
    co = evaluate_cut_out(v, np.minimum(1.0, v), dx0_f, params)
    de = evaluate_decel(v, gx, params, dx0_m=1.2 * v)
    for i in range(8):
        if abs(co.min_gap_m[i]) > 0.3:
            assert (
                simulate_cut_out(v[i], min(1.0, v[i]), dx0_f[i], params).collision
                == (co.collision[i])
            )
        if abs(de.min_gap_m[i]) > 0.3:
            assert (
                simulate_decel(v[i], gx[i], params, dx0=1.2 * v[i]).collision == (de.collision[i])
            )


def test_every_datasheet_names_its_conventions():
    p = CCParams(judgement="overlap", decel_perception="never", contact="lane")
    sheets = [
        cut_in_figure(cut_in_datasheet(Grid(60, 60, 1), Grid(20, 20, 1), Grid(1, 2, 1), p)),
        cut_out_figure(cut_out_datasheet(Grid(40, 60, 20), Grid(1, 2, 1), p)),
        decel_figure(decel_datasheet(Grid(40, 60, 20), Grid(0.5, 1.0, 0.5), p)),
    ]
    for fig in sheets:
        title = fig.get_suptitle()
        assert p.convention_note() in title
        assert "first lateral overlap" in title and "lane-aligned" in title


def test_cli_convention_options(tmp_path, capsys):
    """The options reach the model: the CLI datasheet equals the API's with the same
    conventions, and the output names them."""
    out = tmp_path / "ci"
    args = ["boundary", "cut-in", "-o", str(out), "--ve", "60", "--dv", "30", "--vy", "1"]
    assert main([*args, "--danger-at", "overlap", "--contact", "lane"]) == 0
    printed = capsys.readouterr().out
    assert "first lateral overlap" in printed and "lane-aligned" in printed
    with (out / "cut_in_boundary.csv").open() as fh:
        row = next(csv.DictReader(fh))
    assert float(row["boundary_dx0_m"]) == pytest.approx(26.6)  # 26.543 rounded up
    for scenario, grid, flag, value in (  # each scenario takes its own conventions
        ("cut-in", ["--dv", "30", "--vy", "1"], "--above-ttc", "wait"),
        ("cut-out", ["--vy", "1"], "--cut-out-perception", "no"),
        ("decel", ["--gx", "1"], "--decel-perception", "hard-braking"),
    ):
        assert main(["boundary", scenario, "-o", str(tmp_path / scenario), "--ve", "60", *grid,
                     flag, value]) == 0  # fmt: skip
        assert "not the docs/models.md default" in capsys.readouterr().out
    assert main([*args, "--danger-at", "sometimes"]) == 1  # an unknown convention is refused
    assert "--danger-at: invalid choice: 'sometimes'" in capsys.readouterr().err
