"""Issue 15 item 2: the exact Preventable regions of the cut-in (every colliding interval of
dx0), against hand computation and a dense scan of the evaluator; the datasheet, its CSV and
the R157 expectations use them."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from hiyari.risk.cc.boundary import Grid, cut_in_datasheet
from hiyari.risk.cc.evaluator import evaluate_cut_in
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.r157_points import R157Point, expected_verdicts
from hiyari.risk.cc.regions import cut_in_regions

KMH = 1 / 3.6
A = 0.774 * 9.81


def _relative_braking_distance(dv: float) -> float:
    """Distance (m) the ego closes on the other while braking from closing speed ``dv`` to 0:
    0.6 s ramp to A, then A held (JAMA)."""
    ramp_loss = 0.5 * A * 0.6
    return dv * 0.6 - A * 0.6**2 / 6 + (dv - ramp_loss) ** 2 / (2 * A)


def test_pocket_below_the_colliding_gaps_by_hand():
    """Lane-aligned contact, Ve0 = 60, Vo0 = 42 km/h (closing 5 m/s), Vy = 0.3 m/s: danger
    judgement at 0.375 / 0.3 + 0.4 = 1.65 s. Up to dx0 = 5 x 1.65 = 8.25 m the car is beside
    the ego then (no braking) and the ego is fully past when the car enters its width at
    1.6 / 0.3 = 5.33 s (it has closed 26.7 m > dx0 + 10.1 m): no collision. Above, it brakes
    from 2.4 s and closes 5 x 2.4 + 3.032 = 15.032 m in all, done by 3.36 s: a collision
    iff dx0 < 15.032 m. So the colliding gaps are (8.25, 15.032), not [0, 15.032]."""
    lane = CCParams(contact="lane")
    r = cut_in_regions(np.array([60 * KMH]), np.array([42 * KMH]), np.array([0.3]), lane)
    closed = 5.0 * 2.4 + _relative_braking_distance(5.0)
    assert closed == pytest.approx(15.032, abs=1e-3)
    assert r.intervals(0) == [(pytest.approx(8.25, abs=1e-9), pytest.approx(closed, abs=1e-6))]
    assert r.upper[0] == pytest.approx(closed, abs=1e-6)
    gaps = np.array([0.0, 4.0, 8.2, 8.3, 15.0, 15.1, 30.0])
    hit = evaluate_cut_in(60 * KMH, 42 * KMH, gaps, 0.3, lane).collision
    assert hit.tolist() == [False, False, False, True, True, False, False]
    assert r.contains(np.full(1, 4.0))[0] == bool(hit[1])


@pytest.mark.parametrize(
    "params",
    [
        CCParams(),
        CCParams(contact="lane"),
        CCParams(aeb=True),
        CCParams(judgement="overlap"),
        CCParams(above_ttc="end"),
    ],
    ids=["default", "lane", "aeb", "overlap", "end"],
)
def test_regions_equal_a_dense_scan_of_the_evaluator(params):
    """Every gap of a 5 cm scan from 0 to 120 m collides exactly where the regions say,
    except within the AEB search tolerance of an interval's end."""
    rng = np.random.default_rng(31)
    n = 120
    vo = rng.uniform(8, 100, n) * KMH
    ve = vo + rng.uniform(0, 60, n) * KMH
    vy = np.minimum(rng.uniform(0.1, 3.0, n), vo)
    regions = cut_in_regions(ve, vo, vy, params)
    gaps = np.arange(0.0, 120.0, 0.05)
    m = gaps.size
    hit = evaluate_cut_in(
        np.repeat(ve, m), np.repeat(vo, m), np.tile(gaps, n), np.repeat(vy, m), params
    ).collision.reshape(n, m)
    said = np.stack([regions.contains(np.full(n, g)) for g in gaps], axis=1)
    ends = np.concatenate([regions.lo, regions.hi], axis=1)
    dist = np.nanmin(np.abs(gaps[None, :, None] - ends[:, None, :]), axis=2, initial=np.inf)
    tol = 2e-3 if params.aeb else 1e-6
    differ = (hit != said) & (dist > tol)
    assert not differ.any(), np.argwhere(differ)[:3]
    assert hit.any(axis=1).sum() > n // 3  # not vacuous
    assert (regions.lo[:, 0] > 0).any()  # some have Preventable gaps below their regions


def test_datasheet_marks_pockets_preventable_and_writes_every_interval(tmp_path):
    """The datasheet's regions: a gap below the boundary in a pocket is Preventable (the
    evaluator agrees: no collision), where one boundary would have called it Unpreventable;
    the CSV lists the intervals exactly."""
    sheet = cut_in_datasheet(Grid(40, 80, 20), Grid(10, 40, 10), Grid(0.1, 0.5, 0.1))
    below = sheet.regions.lo[:, 0]
    pocket = np.flatnonzero(below > 0.2)
    assert pocket.size > 5
    v_e, v_o = sheet.ve0_kmh[pocket] * KMH, sheet.vo0_kmh[pocket] * KMH
    mid = 0.5 * below[pocket]
    assert np.all(mid < sheet.boundary_dx0_m[pocket])
    assert not evaluate_cut_in(v_e, v_o, mid, sheet.vy_mps[pocket]).collision.any()
    assert not sheet.regions.rows(pocket).contains(mid).any()
    with sheet.write_csv(tmp_path / "ci.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    for i, row in enumerate(rows):
        cells = [c.split(":") for c in row["colliding_dx0_m"].split(";") if c]
        want = sheet.regions.intervals(i)
        assert len(cells) == len(want)
        for (lo, hi), (w_lo, w_hi) in zip(cells, want, strict=True):
            assert float(lo) == pytest.approx(w_lo, abs=5e-4)
            assert float(hi) == pytest.approx(w_hi, abs=5e-4)


def test_r157_expectation_of_a_pocket_is_preventable():
    """A cut-in test point in a pocket below the boundary expects "preventable"; one inside
    the colliding interval "unpreventable" (the expectations come from the regions)."""
    ve, vo, vy = 60.0, 42.0, 0.3

    def point(dx0: float) -> R157Point:
        return R157Point(
            id=f"p{dx0:g}",
            scenario="cut-in",
            point="boundary-5m",
            ve0_kmh=ve,
            ve0_mps=ve * KMH,
            vo0_kmh=vo,
            vo0_mps=vo * KMH,
            dx0_m=dx0,
            vy_mps=vy,
            gx_max_g=None,
            dx0_f_m=None,
            boundary_m=15.1,
            offset_m=dx0 - 15.1,
            expected="unpreventable",
            cc_min_gap_m=0.0,
        )

    lane = CCParams(contact="lane")
    assert expected_verdicts([point(4.0), point(10.1)], lane) == ["preventable", "unpreventable"]
