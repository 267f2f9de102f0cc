"""Euro NCAP scoring rules (bridge.studies.ncap.scoring, pure) against hand-computed cases from
the assessment protocol's own tables and examples (Safety Assist - Collision Avoidance v10.4.1,
section 3.3): each colour band's boundary speeds fall on the right side, the overlap weights,
the points per test speed, the CCFtap and head-on scores, the FCW test's braking robot, the
speed tolerance, the scenario and protocol totals; results rows scored as the study scores
them; the protocols' grids and the refusals of bad selections."""

from __future__ import annotations

import math

import pytest

from hiyari.bridge.studies.ncap import scoring
from hiyari.bridge.studies.ncap.points import score_row
from hiyari.bridge.studies.ncap.protocols import TESTS, select_tests
from hiyari.bridge.studies.ncap.scoring import Colour, PointScore
from hiyari.errors import HiyariError

G, Y, OR, B, R = Colour.GREEN, Colour.YELLOW, Colour.ORANGE, Colour.BROWN, Colour.RED


@pytest.mark.parametrize(
    ("impact", "colour"),
    [  # SA 3.3.2, CCRs/CCRb at 50 km/h: green <5, yellow 5-15, orange 15-30, brown 30-40
        (0.0, G),
        (4.99, G),
        (5.0, Y),  # a band's lower limit belongs to it (5 <= v < 15 is yellow)
        (14.99, Y),
        (15.0, OR),
        (29.99, OR),
        (30.0, B),
        (39.99, B),
        (40.0, R),
        (50.0, R),  # no reduction
    ],
)
def test_ccr_bands_at_50_kmh_follow_the_protocol_table(impact: float, colour: Colour) -> None:
    assert scoring.ccr_colour("CCRs", 50.0, True, impact) is colour
    assert scoring.ccr_colour("CCRb", 50.0, True, impact) is colour  # CCRb = CCRs at 50 km/h


def test_ccr_bands_of_the_other_speeds_and_the_avoided_point() -> None:
    assert scoring.ccr_colour("CCRs", 30.0, False, 0.0) is G
    assert scoring.ccr_colour("CCRs", 20.0, True, 0.99) is G  # the 10-20 km/h rows: <1 km/h
    assert scoring.ccr_colour("CCRs", 20.0, True, 1.0) is R
    assert scoring.ccr_colour("CCRs", 30.0, True, 24.99) is OR  # 30 km/h: no brown band
    assert scoring.ccr_colour("CCRs", 30.0, True, 25.0) is R
    # CCRm by its relative impact speed; 80 km/h (and 130 km/h, the same row): 5/20/35/50
    assert [scoring.ccr_colour("CCRm", 80.0, True, v) for v in (4, 19, 34, 49, 50)] == [
        G, Y, OR, B, R,
    ]  # fmt: skip
    assert scoring.ccr_bands("CCRm", 130.0) == scoring.ccr_bands("CCRm", 80.0)
    # CCRs above 50 km/h (assumed): the CCRm row of the same closing speed (60 -> CCRm 80)
    assert scoring.ccr_bands("CCRs-FCW", 60.0) == scoring.ccr_bands("CCRm", 80.0)
    assert scoring.ccr_bands("CCRs", 50.0) == scoring.ccr_bands("CCRm", 70.0)  # closing 50
    with pytest.raises(ValueError):
        scoring.ccr_bands("CCFtap", 20.0)


def test_overlap_and_speed_weights_reproduce_the_protocol_formula() -> None:
    # SA 3.3.2: per test speed (s[-50] + s[-75] + 2 s[100] + s[75] + s[50]) / 6 times the
    # speed's points; 15 km/h has 2 points: green, yellow, orange (100 %), brown, red
    # -> (1 + 0.75 + 2 * 0.5 + 0.25 + 0) / 6 = 0.5 of the speed's 2 points
    overlaps = ((-50, G), (-75, Y), (100, OR), (75, B), (50, R))
    pts = [PointScore("CCRs", "day", c, weight=scoring.point_weight("CCRs", 15, o))
           for o, c in overlaps]  # fmt: skip
    assert sum(p.weight for p in pts) == pytest.approx(2.0)
    assert sum(p.weight * p.points_fraction for p in pts) == pytest.approx(1.0)
    assert scoring.point_weight("CCRs", 15, 100) == pytest.approx(2 * 2 / 6)
    assert scoring.point_weight("CCRm", 80, 75) == pytest.approx(2 / 6)
    assert scoring.point_weight("CCRb", None, None) == 1.0
    assert sum(scoring.CCRS_SPEED_POINTS.value.values()) == 14  # type: ignore[attr-defined]
    assert sum(scoring.CCRM_SPEED_POINTS.value.values()) == 15  # type: ignore[attr-defined]
    assert sum(scoring.FCW_SPEED_POINTS.value.values()) == 6  # type: ignore[attr-defined]


def _ccrs_grid(red_speed: float | None = None) -> list[PointScore]:
    pts = []
    for v in scoring.CCRS_SPEED_POINTS.value:  # type: ignore[attr-defined]
        for o in (-50, -75, 100, 75, 50):
            c = R if v == red_speed else G
            pts.append(PointScore("CCRs", "day", c, weight=scoring.point_weight("CCRs", v, o)))
    return pts


def test_the_protocols_scoring_example() -> None:
    """SA 3.3.7.1: CCRs 12 of 14 points (x correction factor 1.02 = 87.4 %), CCFtap 6 of 9
    (66.7 %), head-on 0.5 of 1. hiyari has no verification tests: its correction factor is 1."""
    ccrs = scoring.scenario_score("CCRs", 1.0, _ccrs_grid(red_speed=25.0))  # 25 km/h: 2 pts
    assert ccrs.points == pytest.approx(12 / 14)
    assert round(ccrs.points * 1.02, 3) == 0.874
    tap = [PointScore("CCFtap", "day", G)] * 6 + [PointScore("CCFtap", "day", R)] * 3
    assert scoring.scenario_score("CCFtap", 1.0, tap).points == pytest.approx(0.667, abs=5e-4)
    # head-on: 0.25 per test at a reduction >= 20 km/h (CCFhos both), none for CCFhol
    hos = [PointScore("CCFhos", "day", scoring.headon_colour(v, True, v - 20.0)) for v in (50, 70)]
    hol = [PointScore("CCFhol", "day", scoring.headon_colour(v, True, v - 5.0)) for v in (50, 70)]
    total = scoring.protocol_score(
        "c2c",
        [scoring.scenario_score("CCFhos", 0.5, hos), scoring.scenario_score("CCFhol", 0.5, hol)],
    )
    assert total.points == pytest.approx(0.5) and total.max_points == 1.0


def test_ccrs_scores_nothing_when_a_point_up_to_20_kmh_was_hit() -> None:
    pts = _ccrs_grid()
    assert scoring.scenario_score("CCRs", 1.0, pts).points == pytest.approx(1.0)
    pts[0] = PointScore("CCRs", "day", G, weight=pts[0].weight, voids_scenario=True)
    assert scoring.scenario_score("CCRs", 1.0, pts).points == 0.0


@pytest.mark.parametrize(
    ("impact", "colour"),
    [  # test speed 50 km/h: reduction 20 -> full (green), 10 -> half (orange), less -> red
        (30.0, G),
        (30.01, OR),
        (40.0, OR),
        (40.01, R),
    ],
)
def test_headon_reduction_boundaries(impact: float, colour: Colour) -> None:
    assert scoring.headon_colour(50.0, True, impact) is colour
    assert scoring.headon_colour(50.0, False, 0.0) is G
    assert scoring.fraction(OR) * 0.25 == 0.125  # the protocol's half points


def test_fcw_test_brakes_1_2_s_after_the_warning_at_4_mps2() -> None:
    # by hand: 55 km/h warned at TTC 2.0 s; the pedal moves at +1.2 s, 0.8 s * v before the
    # target; the deceleration rises linearly to 4 m/s^2 over 0.2 s, then is held
    v = 55 / 3.6
    gap = v * (2.0 - 1.2)
    x_ramp, v_ramp = v * 0.2 - (4 / 0.2) * 0.2**3 / 6, v - 4 * 0.2 / 2
    expected = math.sqrt(v_ramp**2 - 2 * 4 * (gap - x_ramp)) * 3.6  # 43.77 km/h
    assert scoring.fcw_impact_speed(55.0, 2.0) == pytest.approx(expected, abs=1e-6)
    assert scoring.fcw_impact_speed(55.0, 1.2) == 55.0  # no time to brake
    assert scoring.fcw_impact_speed(55.0, None) == 55.0  # no warning
    assert scoring.fcw_impact_speed(55.0, 4.0) == 0.0  # stops short
    # 55 km/h bands (CCRm 75 row, assumed): green <5, yellow <15, orange <30, brown <45
    assert scoring.fcw_colour(55.0, 2.0, True, 55.0) == (B, pytest.approx(expected))
    assert scoring.fcw_colour(55.0, 2.0, True, 10.0) == (Y, 10.0)  # the AEB did better
    assert scoring.fcw_colour(55.0, None, False, 0.0) == (G, 0.0)  # the AEB alone avoided


def test_fractions_and_speed_tolerance() -> None:
    assert [scoring.fraction(c) for c in Colour] == [1.0, 0.75, 0.5, 0.25, 0.0]
    # C2C 8.4.2: test speed +1.0 / -0 km/h, widened by the 0.1 km/h measuring accuracy
    assert scoring.speed_held([50.0, 51.1], 50.0) == (True, 51.1)
    assert scoring.speed_held([49.9], 50.0) == (True, 49.9)
    assert scoring.speed_held([51.2, 50.0], 50.0) == (False, 51.2)
    assert scoring.speed_held([50.0, 49.8], 50.0) == (False, 49.8)
    assert scoring.speed_held([], 50.0) == (True, 50.0)


def test_vru_bands_and_totals_stay_as_assumed() -> None:
    # reference 40 km/h: bands at 75 / 50 / 25 % speed reduction = impact 10 / 20 / 30 km/h
    assert [scoring.impact_colour(True, v, 40.0) for v in (10.0, 10.01, 20.01, 30.01)] == [
        Y, OR, B, R,
    ]  # fmt: skip
    assert scoring.impact_colour(False, 0.0, 40.0) is G
    with pytest.raises(ValueError):
        scoring.impact_colour(True, 5.0, 0.0)
    pts = [PointScore("CPNA-25", "day", c) for c in (G, Y, OR, R)]
    pts += [PointScore("CPNA-25", "night", G), PointScore("CPNA-25", "night", None, "failed")]
    s = scoring.scenario_score("CPNA-25", 1.0, pts)
    # day: (1 + .75 + .5 + 0) / 4 = .5625; night: (1 + 0) / 2 = .5; halves: .53125
    assert s.points == pytest.approx(0.53125) and (s.tested, s.not_tested) == (5, 1)
    assert scoring.scenario_score("CPTAfo-50", 0.5, pts).points == 0.0
    total = scoring.protocol_score("vru", [s, scoring.ScenarioScore("CBNA-50", 0.5, 2.0, 1, 0)])
    assert total.points == pytest.approx(1.03125) and total.percent == pytest.approx(34.375)


def _row(**kw: object) -> dict:
    row = {"status": "ok", "error": "", "lighting": "day", "row": "50", "col": "100",
           "test_speed_kmh": "50.0", "speed_before_window_kmh": "50.0", "contact": "True",
           "impact_speed_kmh": "30.0", "relative_impact_speed_kmh": "12.0",
           "reference_kmh": "40.0", "warning_ttc_s": ""}  # fmt: skip
    return {**row, **{k: str(v) for k, v in kw.items()}}


def test_rows_scored_as_the_protocol_measures() -> None:
    t = {x.key: x for x in TESTS}
    # CCRm: the relative impact speed counts (12 km/h at 50 km/h: yellow, 5 <= v < 15)
    assert score_row(t["CCRm"], _row()).colour is Y
    # CCRs: the VUT's impact speed (30 km/h at 50 km/h: brown); its weight: 1 point * 2/6
    s = score_row(t["CCRs"], _row())
    assert s.colour is B and s.weight == pytest.approx(2 / 6) and not s.voids_scenario
    assert score_row(t["CCRs"], _row(row=20, test_speed_kmh=20, speed_before_window_kmh=20,
                                     impact_speed_kmh=3)).voids_scenario  # fmt: skip
    # CCRb: impact speed of the VUT, the CCRs 50 km/h bands
    assert score_row(t["CCRb"], _row(row=12, col=6)).colour is B
    # CPNA: the ego's speed against the reference (30 of 40: 25 % -> brown, assumed)
    assert score_row(t["CPNA-25"], _row()).colour is B
    assert score_row(t["CCFtap"], _row()).colour is R
    assert score_row(t["CCFtap"], _row(contact=False)).colour is G
    assert score_row(t["CCFhos"], _row()).colour is G  # 50 -> 30 km/h: 20 km/h less
    fcw = _row(row=55, test_speed_kmh=55, speed_before_window_kmh=55, warning_ttc_s=2.3)
    assert score_row(t["CCRs-FCW"], {**fcw, "contact": "False"}).colour is G
    assert score_row(t["CCRs-FCW"], {**fcw, "impact_speed_kmh": "55.0"}).colour is B
    early = score_row(t["CPNA-25"], _row(speed_before_window_kmh=46.0))
    assert early.colour is None and "46.0 km/h before the test window" in early.not_tested
    fast = score_row(t["CCRs"], _row(speed_before_window_kmh=51.5))
    assert fast.colour is None and "too fast" in fast.not_tested
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
    assert not scoring.CCR_BANDS_50.assumed and "3.3.2" in scoring.CCR_BANDS_50.source
    assert scoring.CCRS_BANDS.assumed and "BeamNG" in scoring.CCRS_BANDS.source
    assert not scoring.FCW_REACTION_S.assumed and "8.4.6" in scoring.FCW_REACTION_S.source
    assert scoring.POINT_WEIGHTS.assumed and scoring.REDUCTION_BANDS.assumed
    c2c = {t.key: t.max_points for t in TESTS if t.protocol == "c2c"}
    assert c2c == scoring.C2C_POINTS.value and not any(
        t.points_assumed for t in TESTS if t.protocol == "c2c"
    )
    # hiyari's C2C tests carry 5.5 of the 9 points; CCCscp (3) and HMI (0.5) are the rest
    assert sum(c2c.values()) + 3.0 + 0.5 == scoring.C2C_PROTOCOL_POINTS.value
    assert all(t.points_assumed for t in TESTS if t.protocol == "vru")


def test_protocol_selection() -> None:
    assert {t.protocol for t in select_tests("all")} == {"c2c", "vru"}
    assert [t.key for t in select_tests("c2c", ("CCRs",))] == ["CCRs"]
    with pytest.raises(HiyariError, match="unknown protocol 'pedestrian'"):
        select_tests("pedestrian")
    with pytest.raises(HiyariError, match="CPNA-25 not in protocol c2c"):
        select_tests("c2c", ("CPNA-25",))
