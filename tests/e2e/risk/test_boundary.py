"""Preventable boundaries: the seed's statement, exactness against the evaluator, shape
properties, files and plots."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from matplotlib.image import imread

from hiyari.bridge.cli.main import main
from hiyari.bridge.studies.report.datasheets import plot_cut_in, plot_cut_out, plot_decel
from hiyari.errors import HiyariError
from hiyari.risk.cc.boundary import (
    Grid,
    cut_in_boundary,
    cut_in_datasheet,
    cut_out_boundary,
    cut_out_datasheet,
    decel_boundary_gap,
    decel_datasheet,
)
from hiyari.risk.cc.evaluator import evaluate_cut_in, evaluate_cut_out, evaluate_decel
from hiyari.risk.cc.model import CCParams

KMH = 1 / 3.6


def test_seed_no_deceleration_boundary_at_or_below_60kmh():
    """JAMA Fig. 30 NOTE: at <= 60 km/h (THW 2 s, Gx_max up to 1.0 g) no Preventable boundary
    appears: the C&C driver avoids every lead deceleration there."""
    sheet = decel_datasheet(Grid(10, 60, 0.5), Grid(0.01, 1.0, 0.01))
    assert sheet.preventable.all()
    assert sheet.min_gap_m.min() > 1.0
    # and the statement is not vacuous: a shorter following gap does collide at 60 km/h
    short = evaluate_decel(60 * KMH, 1.0, CCParams(thw_s=1.0))
    assert short.collision[0]


def test_decel_boundary_gap_is_exact():
    ve = np.array([30.0, 60.0, 100.0, 130.0]) * KMH
    gx = np.array([1.0, 0.5, 1.0, 0.8])
    for p in (CCParams(), CCParams(aeb=True)):
        b = decel_boundary_gap(ve, gx, p)
        assert np.all(b > 0) and np.all(b < 2 * ve)
        assert not evaluate_decel(ve, gx, p, dx0_m=b + 2e-3).collision.any()
        assert evaluate_decel(ve, gx, p, dx0_m=b - 0.01).collision.all()


@pytest.mark.parametrize(("aeb", "above_ttc"), [(False, "end"), (True, "end"), (False, "wait"),
                                                (True, "wait")])  # fmt: skip
def test_cut_in_boundary_is_exact(aeb, above_ttc):
    """At the boundary (+ a hair) no collision, 1 cm below a collision; +1, +2, +10, +30 m
    never collide; rows without a Preventable gap (only when the reaction waits for TTC = 2 s)
    collide even at 200 m."""
    p = CCParams(aeb=aeb, above_ttc=above_ttc)
    rng = np.random.default_rng(11)
    n = 400
    vo = rng.uniform(5, 100, n) * KMH
    ve = vo + rng.uniform(0, 70, n) * KMH
    vy = np.maximum(np.floor(np.minimum(rng.uniform(0.1, 3.0, n), vo) * 10) / 10, 0.1)
    b = cut_in_boundary(ve, vo, vy, p)
    fin = np.isfinite(b)
    pos = fin & (b > 0.02)
    assert pos.sum() > 200
    tol = 2e-3 if aeb else 1e-9
    assert not evaluate_cut_in(ve[fin], vo[fin], b[fin] + tol, vy[fin], p).collision.any()
    assert evaluate_cut_in(ve[pos], vo[pos], b[pos] - 0.01, vy[pos], p).collision.all()
    for off in (1, 2, 10, 30):
        assert not evaluate_cut_in(ve[fin], vo[fin], b[fin] + off, vy[fin], p).collision.any()
    if above_ttc == "end":
        assert fin.all()
        return
    assert (~fin).sum() > 0
    assert evaluate_cut_in(ve[~fin], vo[~fin], 200.0, vy[~fin], p).collision.all()


def test_cut_in_boundary_shape():
    """Lane-aligned contact: the boundary grows with the relative speed and shrinks as the
    cut-in gets faster (earlier judgement); it is the same for every Ve0 at a given Ve0 - Vo0
    (symmetry); with no closing speed it is 0. With the reaction waiting for TTC = 2 s
    (``above_ttc="wait"``), past about 52 km/h closing speed it comes too late at any gap (no
    Preventable gap); the AEB moves that limit beyond 60 km/h."""
    lane = CCParams(contact="lane", above_ttc="wait")
    sheet = cut_in_datasheet(Grid(10, 130, 1), Grid(0, 60, 1), Grid(0.1, 3.0, 0.1), lane)
    dv, vy, b = sheet.dv_kmh, sheet.vy_mps, sheet.boundary_dx0_m
    assert np.all(b[dv == 0] == 0)
    for v in (0.1, 0.5, 1.0, 3.0):
        sel = np.isclose(vy, v)
        # one value per relative speed whatever Ve0
        for d in np.unique(dv[sel]):
            vals = b[sel & (dv == d)]
            assert np.all(vals == vals[0])
        per_dv = np.array([b[sel & (dv == d)][0] for d in np.unique(dv[sel])])
        finite = per_dv[np.isfinite(per_dv)]
        assert np.all(np.diff(finite) >= 0)
    for d in (10, 30, 50):
        sel = dv == d
        per_vy = np.array([b[sel & np.isclose(vy, v)][0] for v in np.unique(vy[sel])])
        assert np.all(np.diff(per_vy) <= 1e-9)
    assert np.isfinite(b[dv <= 52]).all()
    assert np.isinf(b[dv >= 53]).all()
    aeb = cut_in_datasheet(
        Grid(60, 60, 1), Grid(50, 60, 1), Grid(0.5, 3.0, 0.5),
        CCParams(aeb=True, contact="lane", above_ttc="wait"),
    )  # fmt: skip
    assert np.isfinite(aeb.boundary_dx0_m).all()


def test_default_cut_in_boundary_is_finite_at_any_closing_speed(tmp_path):
    """Issue 36: a careful driver does not hit a car cutting in 100 m ahead. By default a
    cut-in whose TTC at danger judgement is >= 2 s is not critical, so at Ve0 = 100 km/h every
    (Ve0 - Vo0, Vy) row has a finite boundary. Ve0 - Vo0 = 60 km/h (16.667 m/s), Vy = 1 m/s,
    lane-aligned: danger at 0.375 + 0.4 s, boundary = 16.667 x (0.775 + 2) = 46.25 m (the
    gap at which TTC at danger is 2 s; below it the reaction at danger comes too late:
    16.667 x 1.525 + the relative braking distance 22.70 m = 48.12 m > 46.25 m)."""
    dv = 60 * KMH
    lane = cut_in_datasheet(Grid(100, 100, 1), Grid(60, 60, 1), Grid(1, 1, 1),
                            CCParams(contact="lane"), resolution_m=None)  # fmt: skip
    assert lane.boundary_dx0_m[0] == pytest.approx(dv * 2.775, abs=1e-6)
    assert lane.boundary_dx0_m[0] == pytest.approx(46.25, abs=5e-3)
    out = tmp_path / "b"
    assert main(["boundary", "cut-in", "--ve", "100:100:1", "-o", str(out)]) == 0
    with (out / "cut_in_boundary.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 61 * 30  # dv 0..60 km/h x Vy 0.1..3.0 m/s
    assert all(np.isfinite(float(r["boundary_dx0_m"])) for r in rows)
    # with the Annex G heading too, the boundary is where TTC at danger is 2 s:
    # 16.667 x (0.375 / Vy + 0.4 + 2) = 52.5 m at Vy = 0.5 m/s, 102.5 m at 0.1 m/s
    at = {r["vy_mps"]: float(r["boundary_dx0_m"]) for r in rows if r["dv_kmh"] == "60"}
    assert at["0.5"] == pytest.approx(52.5) and at["0.1"] == pytest.approx(102.5)


@pytest.mark.parametrize("aeb", [False, True])
def test_cut_out_boundary_is_exact_and_grows_with_speed(aeb):
    p = CCParams(aeb=aeb)
    ve = np.repeat(np.arange(20, 131, 10) * KMH, 3)
    vy = np.tile([0.5, 1.0, 3.0], ve.size // 3)
    b = cut_out_boundary(ve, vy, p)
    pos = b > 0.02
    tol = 2e-3 if aeb else 1e-9
    assert not evaluate_cut_out(ve[pos], vy[pos], b[pos] + tol, p).collision.any()
    assert evaluate_cut_out(ve[pos], vy[pos], b[pos] - 0.01, p).collision.all()
    for v in (0.5, 1.0, 3.0):
        assert np.all(np.diff(b[vy == v]) >= 0)
    assert np.all(b[vy == 0.5] >= b[vy == 3.0])


def test_aeb_boundaries_not_above_driver_only():
    grid = (Grid(20, 130, 10), Grid(0.5, 3.0, 0.5))
    plain = cut_out_datasheet(*grid).boundary_dx0_f_m
    aeb = cut_out_datasheet(*grid, params=CCParams(aeb=True)).boundary_dx0_f_m
    assert np.all(aeb <= plain + 1e-9) and np.any(aeb < plain - 1)


def test_datasheet_csv_and_png_round_trip(tmp_path):
    cut_in = cut_in_datasheet(Grid(20, 80, 20), Grid(0, 60, 10), Grid(0.5, 3.0, 0.5))
    path = cut_in.write_csv(tmp_path / "ci.csv")
    with path.open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == cut_in.ve0_kmh.size
    got = np.array([float(r["boundary_dx0_m"]) for r in rows])
    assert np.array_equal(np.isinf(got), np.isinf(cut_in.boundary_dx0_m))
    fin = np.isfinite(got)
    assert np.allclose(got[fin], cut_in.boundary_dx0_m[fin], atol=5e-4)
    # 0.1 m resolution: every finite boundary is a multiple of 0.1 m
    assert np.allclose(np.round(got[fin] * 10), got[fin] * 10, atol=1e-6)
    cut_out = cut_out_datasheet(Grid(10, 130, 10), Grid(0.5, 3.0, 0.5))
    decel = decel_datasheet(Grid(10, 130, 10), Grid(0.1, 1.0, 0.1))
    with (cut_out.write_csv(tmp_path / "co.csv")).open() as fh:
        assert len(list(csv.DictReader(fh))) == cut_out.ve0_kmh.size
    with (decel.write_csv(tmp_path / "de.csv")).open() as fh:
        rows = list(csv.DictReader(fh))
    assert {r["preventable"] for r in rows} == {"true"}
    for plot, sheet, name in (
        (plot_cut_in, cut_in, "ci.png"),
        (plot_cut_out, cut_out, "co.png"),
        (plot_decel, decel, "de.png"),
    ):
        image = imread(plot(sheet, tmp_path / name))
        assert image.ndim == 3 and image.shape[0] > 300 and image.shape[1] > 500
        assert image[..., :3].std() > 0.05  # not a blank canvas


@pytest.mark.parametrize(
    ("call", "needle"),
    [
        (lambda: Grid.parse("10:5:1", "--ve"), "stop below start"),
        (lambda: Grid.parse("1:5:0", "--ve"), "step must be > 0"),
        (lambda: Grid.parse("a:b", "--ve"), "start:stop:step"),
        (lambda: cut_in_datasheet(Grid(-10, 30, 10)), "speeds must be >= 0"),
        (lambda: cut_in_datasheet(vy_mps=Grid(0, 3, 0.5)), "lateral velocity must be > 0"),
        (lambda: cut_in_datasheet(vy_mps=Grid(0.5, 9, 0.5)), "under 0.5 s"),
        (lambda: cut_in_datasheet(Grid(10, 400, 10)), "beyond"),
        (lambda: cut_in_datasheet(Grid(10, 10, 1), Grid(10, 10, 1)), "no feasible"),
        (lambda: decel_datasheet(gx_max_g=Grid(0.5, 1.5, 0.5)), "road friction"),
    ],
)
def test_bad_ranges_refused(call, needle):
    with pytest.raises(HiyariError, match=needle):
        call()
