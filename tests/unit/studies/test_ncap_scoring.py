"""Euro NCAP scoring rules (bridge.studies.ncap.scoring, pure) against hand-computed cases: each
colour band's boundary speeds fall on the right side, FCW's TTC boundary, the speed-held rule,
the scenario and protocol totals; results rows scored as the study scores them; the protocols'
grids and the refusals of bad selections."""

from __future__ import annotations

import pytest

from hiyari.bridge.studies.ncap import scoring
from hiyari.bridge.studies.ncap.points import score_row
from hiyari.bridge.studies.ncap.protocols import TESTS, select_tests
from hiyari.bridge.studies.ncap.scoring import Colour, PointScore
from hiyari.errors import HiyariError

G, Y, OR, B, R = Colour.GREEN, Colour.YELLOW, Colour.ORANGE, Colour.BROWN, Colour.RED


@pytest.mark.parametrize(
    ("impact", "colour"),
    [  # reference 40 km/h: bands at 75 / 50 / 25 % speed reduction = impact 10 / 20 / 30 km/h
        (0.0, Y),  # touched at walking pace: not avoided, reduction 100 %
        (10.0, Y),  # exactly 75 %: the boundary belongs to the better band
        (10.01, OR),
        (20.0, OR),
        (20.01, B),
        (30.0, B),
        (30.01, R),
        (40.0, R),  # no reduction
        (45.0, R),  # faster than the reference (a target braking into the ego)
    ],
)
def test_impact_bands_boundaries(impact: float, colour: Colour) -> None:
    assert scoring.impact_colour(True, impact, 40.0) is colour


def test_avoided_is_green_and_reference_must_be_positive() -> None:
    assert scoring.impact_colour(False, 0.0, 40.0) is G
    with pytest.raises(ValueError):
        scoring.impact_colour(True, 5.0, 0.0)


def test_fcw_and_avoidance_colours() -> None:
    assert scoring.fcw_colour(2.1) is G
    assert scoring.fcw_colour(2.09) is R
    assert scoring.fcw_colour(None) is R
    assert scoring.avoidance_colour(False) is G and scoring.avoidance_colour(True) is R


def test_fractions_and_speed_held() -> None:
    assert [scoring.fraction(c) for c in Colour] == [1.0, 0.75, 0.5, 0.25, 0.0]
    assert scoring.speed_held([50.9, 49.2], 50.0) == (True, 50.9)  # furthest from 50
    assert scoring.speed_held([50.0, 48.9], 50.0) == (False, 48.9)
    assert scoring.speed_held([], 50.0) == (True, 50.0)


def test_scenario_and_protocol_totals_by_hand() -> None:
    pts = [PointScore("CPNA-25", "day", c) for c in (G, Y, OR, R)]
    pts += [PointScore("CPNA-25", "night", G), PointScore("CPNA-25", "night", None, "failed")]
    pts += [PointScore("CBNA-50", "day", B)]
    s = scoring.scenario_score("CPNA-25", 1.0, pts)
    # day: (1 + .75 + .5 + 0) / 4 = .5625; night: (1 + 0) / 2 = .5; halves: .53125
    assert s.points == pytest.approx(0.53125) and (s.tested, s.not_tested) == (5, 1)
    b = scoring.scenario_score("CBNA-50", 2.0, pts)
    assert b.points == pytest.approx(0.5)
    total = scoring.protocol_score("vru", [s, b])
    assert total.points == pytest.approx(1.03125) and total.max_points == 3.0
    assert total.percent == pytest.approx(34.375)
    assert scoring.scenario_score("CPTAfo-50", 0.5, pts).points == 0.0


def _row(**kw: object) -> dict:
    row = {"status": "ok", "error": "", "lighting": "day", "test_speed_kmh": "50.0",
           "speed_before_window_kmh": "50.0", "contact": "True", "impact_speed_kmh": "30.0",
           "relative_impact_speed_kmh": "12.0", "reference_kmh": "40.0", "warning_ttc_s": ""}  # fmt: skip
    return {**row, **{k: str(v) for k, v in kw.items()}}


def test_rows_scored_as_the_protocol_measures() -> None:
    t = {x.key: x for x in TESTS}
    # CCRm: the closing speed counts (12 of 40 km/h: 70 % reduction -> orange)
    assert score_row(t["CCRm"], _row()).colour is OR
    # CPNA: the ego's speed counts (30 of 40: 25 % -> brown)
    assert score_row(t["CPNA-25"], _row()).colour is B
    assert score_row(t["CCFtap"], _row()).colour is R
    assert score_row(t["CCFtap"], _row(contact=False)).colour is G
    assert score_row(t["CCRs-FCW"], _row(warning_ttc_s=2.3)).colour is G
    early = score_row(t["CPNA-25"], _row(speed_before_window_kmh=46.0))
    assert early.colour is None and "46.0 km/h before the test window" in early.not_tested
    failed = score_row(t["CPNA-25"], _row(status="failed", error="HiyariError: x"))
    assert failed.colour is None and failed.not_tested == "run failed: HiyariError: x"


def test_a_run_not_tested_scores_nothing_even_without_contact() -> None:
    """Issue 30, item 1: an ego that braked before the target moved avoided nothing."""
    t = {x.key: x for x in TESTS}
    cause = "braked at 0.30 s, before the disturbance at 1.50 s"
    s = score_row(t["CCFtap"], _row(contact=False, tested=False, untested_cause=cause))
    assert s.colour is None and s.not_tested == f"not tested: {cause}"
    assert score_row(t["CCFtap"], _row(contact=False, tested=True)).colour is G


def test_every_rule_names_its_source_and_the_unfound_ones_are_marked() -> None:
    for rule in scoring.RULES:
        assert rule.source and isinstance(rule.assumed, bool)
    assert scoring.FCW_MIN_TTC_S.assumed and "NHTSA" in scoring.FCW_MIN_TTC_S.source


def test_protocol_selection() -> None:
    assert {t.protocol for t in select_tests("all")} == {"c2c", "vru"}
    assert [t.key for t in select_tests("c2c", ("CCRs",))] == ["CCRs"]
    with pytest.raises(HiyariError, match="unknown protocol 'pedestrian'"):
        select_tests("pedestrian")
    with pytest.raises(HiyariError, match="CPNA-25 not in protocol c2c"):
        select_tests("c2c", ("CPNA-25",))
