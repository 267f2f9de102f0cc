"""Euro NCAP 2026 Crash Avoidance - Frontal Collisions scoring (bridge.studies.ncap.scoring2026,
pure) against hand-computed cases: the protocol's own 60 km/h CMRs table (CA-FC v1.1 4.2.4)
with each boundary on the right side, the lower speeds' bands of Euro NCAP's rating
calculator, the head-on speed reduction, the FCW TTC and FCW robot cells, the Standard Range
normalisation (5.3.1) with the FCW grids counting in their AEB scenario, and results rows
scored as the study scores them."""

from __future__ import annotations

import pytest

from hiyari.bridge.studies.ncap import scoring2026 as s26
from hiyari.bridge.studies.ncap.points import score_row
from hiyari.bridge.studies.ncap.protocols import CA2026, select_tests
from hiyari.bridge.studies.ncap.scoring import Colour, PointScore
from hiyari.bridge.studies.ncap.study import totals

G, Y, OR, B, R = Colour.GREEN, Colour.YELLOW, Colour.ORANGE, Colour.BROWN, Colour.RED


@pytest.mark.parametrize(
    ("impact", "colour"),
    [  # CA-FC 4.2.4, 60 km/h CMRs: green 0, yellow 0-10, orange 10-20, brown 20-30, red > 30
        (0.0, Y),  # a touch at 0 km/h is a contact: not green
        (0.5, Y),
        (10.0, Y),  # the upper limit belongs to the band (0 < v <= 10)
        (10.01, OR),
        (20.0, OR),
        (20.01, B),
        (30.0, B),
        (30.01, R),
        (60.0, R),
    ],
)
def test_relative_impact_bands_follow_the_60_kmh_table(impact: float, colour: Colour) -> None:
    assert s26.rel_colour(60.0, True, impact) is colour


def test_relative_impact_bands_of_the_lower_speeds_and_the_avoided_cell() -> None:
    assert s26.rel_colour(10.0, False, 0.0) is G
    assert s26.rel_colour(20.0, True, 0.3) is R  # 10 and 20 km/h: avoid or red
    assert [s26.rel_colour(30.0, True, v) for v in (10.0, 10.5)] == [B, R]
    assert [s26.rel_colour(40.0, True, v) for v in (10.0, 15.0, 20.0, 20.5)] == [OR, B, B, R]
    assert s26.rel_colour(130.0, True, 25.0) is B  # 50 km/h and above share a row


def test_head_on_speed_reduction_bands() -> None:
    # VUT at 50 km/h: reduction = 50 - impact; <=10 red, <=20 orange, above green
    assert [s26.reduction_colour(50.0, True, v) for v in (40.0, 39.9, 30.0, 29.9)] == [
        R, OR, OR, G,
    ]  # fmt: skip
    assert s26.reduction_colour(80.0, True, 20.0) is G  # 60 km/h less: not penalised
    assert s26.reduction_colour(30.0, False, 0.0) is G


def test_fcw_cells() -> None:
    assert [s26.fcw_ttc_colour(t) for t in (1.7, 1.69, None)] == [G, R, R]
    # CCRs FCW at 60 km/h, warned at a true TTC of 3.0 s, no AEB braking: the robot starts
    # 1.2 s later with 30.0 m left; its 0.2 s pedal ramp (jerk 20 m/s^3) covers 3.307 m and
    # ends at 16.267 m/s; -4 m/s^2 over the last 26.693 m leaves sqrt(16.267^2 - 8 * 26.693)
    # = 7.145 m/s = 25.7 km/h: brown (20-30 km/h at 50 km/h and above)
    assert s26.fcw_rel_colour(60.0, 3.0, True, 60.0) is B
    assert s26.fcw_rel_colour(60.0, None, True, 60.0) is R  # no warning, no robot
    assert s26.fcw_rel_colour(60.0, 3.0, False, 0.0) is G  # the AEB avoided it


def test_standard_range_points_and_fcw_grids_counting_in_their_scenario() -> None:
    tests = select_tests(CA2026)
    assert sum(t.max_points for t in tests) == pytest.approx(42.0)
    by_key = {t.key: t for t in tests}
    assert by_key["CCRs-FCW"].scenario_key == "CCRs" and by_key["CCRs-FCW"].max_points == 0
    # CCRs: 25 AEB cells green and 15 FCW cells red: 25 / 40 of the scenario's 1.2 points
    pts = [PointScore("CCRs", "day", G)] * 25 + [PointScore("CCRs", "day", R)] * 15
    # CPNA: day all green, night all orange (0.5): each lighting half of its 1.0 point
    pts += [PointScore("CPNA", "day", G)] * 18 + [PointScore("CPNA", "night", OR)] * 18
    (total,) = totals([by_key["CCRs"], by_key["CCRs-FCW"], by_key["CPNA"]], pts, CA2026)
    got = {s.scenario: round(s.points, 6) for s in total.scenarios}
    assert got == {"CCRs": 0.75, "CPNA": 0.75}
    assert total.max_points == pytest.approx(2.2)


def _row(**kw: object) -> dict:
    row = {"status": "ok", "tested": "True", "lighting": "day", "row": "50", "col": "50",
           "test_speed_kmh": "50", "speed_before_window_kmh": "50.0", "contact": "True",
           "impact_speed_kmh": "25.0", "relative_impact_speed_kmh": "5.0",
           "reference_kmh": "50", "warning_ttc_s": ""}  # fmt: skip
    return row | {k: str(v) for k, v in kw.items()}


def test_results_rows_scored_with_the_2026_rules() -> None:
    t = {x.key: x for x in select_tests(CA2026)}
    # CCRm: judged by the relative impact speed (5 km/h at 50: yellow), weight 1 per cell
    s = score_row(t["CCRm"], _row())
    assert (s.scenario, s.colour, s.weight) == ("CCRm", Y, 1.0)
    assert score_row(t["CPNA"], _row()).colour is B  # crossing: the VUT's 25 km/h
    assert score_row(t["CCCscp"], _row()).colour is R  # avoidance only
    assert score_row(t["CPLA-FCW"], _row(warning_ttc_s=1.8)).scenario == "CPLA"
    assert score_row(t["CPLA-FCW"], _row(warning_ttc_s=1.8)).colour is G
    ccrs = score_row(t["CCRs"], _row(test_speed_kmh=20, row=20, speed_before_window_kmh=20))
    assert ccrs.colour is R and ccrs.voids_scenario  # a contact up to 20 km/h voids CCRs
    late = score_row(t["CCRs"], _row(speed_before_window_kmh="44.0"))
    assert late.colour is None and "braked before" in late.not_tested


def test_crossing_grids_have_a_column_per_speed_and_side() -> None:
    from hiyari.bridge.studies.report.ncap.grids import _order

    t = {x.key: x for x in select_tests(CA2026)}
    assert (t["CCCscp"].col, t["CCCscp"].col2) == ("Target_final_speed_kph", "ImpactSide")
    assert _order(["20/1", "10/1", "10/-1", "20/-1"]) == ["10/-1", "10/1", "20/-1", "20/1"]
    assert _order(["50", "25", "75"]) == ["25", "50", "75"]
