"""Euro NCAP 2026 Crash Avoidance - Frontal Collisions scoring rules, pure (no simulation):
the colour band of one Standard Range grid cell and the scenarios' points. The tests, the grid
cells and the shared pieces (colour fractions, the FCW robot, the speed tolerance, the points
totals) are the 2023 code path's (bridge.studies.ncap.scoring, protocols).

Sources (docs/guide/ncap.md has the table):

- ``CAFC``: Euro NCAP Crash Avoidance - Frontal Collisions Protocol v1.1 (October 2025), read
  in a public transcription of its text: section 4.2.4 (the 60 km/h CMRs colour table),
  4.3.2 (VUT speed +1.0 km/h), 4.3.3 (FCW robot 1.2 s, -4 m/s^2), 5.2 (criteria: which KPI
  each scenario is judged by; Vimpact avoidance bands; FCW TTC 1.7 s), 5.3.1 (sub-score per
  colour, normalised over the Standard Range's grid cells).
- ``RATING``: Euro NCAP's rating calculator ``euroncap-rating-2026`` 5.4.9 (PyPI; repository
  Euro-NCAP/euroncap_rating_2026, Apache-2.0): ``crash_avoidance/matrix_processing.py``
  (the relative-impact-speed bands per VUT speed, the protocol's Figure 5-1, whose numbers are
  not in the text; the speed-reduction bands of Figure 5-2) and ``crash_avoidance/
  data_model.py`` ``TOTAL_SCORES`` (each scenario's Standard Range points).

Speeds in km/h at this module's edge (the protocol's unit), times in s.
"""

from __future__ import annotations

from collections.abc import Mapping

from hiyari.bridge.studies.ncap.scoring import Bands, Colour, Rule, fcw_impact_speed

CAFC = "CA-FC protocol v1.1 (2025)"
RATING = "euroncap-rating-2026 5.4.9 (Euro NCAP's rating calculator)"
CAFC_TEST = "Euro NCAP Crash Avoidance - Frontal Collisions Protocol v1.1 (October 2025)"
CAFC_ASSESSMENT = (
    "Euro NCAP CA-FC v1.1 section 5 (Standard Range), with the bands and scenario points of "
    "Euro NCAP's rating calculator euroncap-rating-2026 5.4.9"
)

_G, _Y, _O, _B, _R = Colour.GREEN, Colour.YELLOW, Colour.ORANGE, Colour.BROWN, Colour.RED
_REL: dict[int, Bands] = {
    10: ((_G, 0.0),),
    20: ((_G, 0.0),),
    30: ((_G, 0.0), (_B, 10.0)),
    40: ((_G, 0.0), (_O, 10.0), (_B, 20.0)),
    50: ((_G, 0.0), (_Y, 10.0), (_O, 20.0), (_B, 30.0)),
}
#: Car & PTW Rear and VRU crossing / longitudinal AEB: colour by Vrel_impact per VUT speed.
REL_BANDS = Rule(
    "2026: colour by relative impact speed, per VUT speed (km/h)",
    _REL,
    f"{RATING} matrix_processing.py (mitigation_or_avoidance_thresholds; 50 km/h and above "
    f"share the 50 row) reading {CAFC} Figure 5-1. Its 60 km/h row equals {CAFC} 4.2.4's "
    "table (green 0, yellow 0-10, orange 10-20, brown 20-30, red above 30). A band's upper "
    "limit belongs to it (4.2.4: 0 < v <= 10 is yellow)",
    assumed=False,
    shown="10, 20: green 0, else red; 30: brown <=10; 40: orange <=10, brown <=20; "
    "50 and above: yellow <=10, orange <=20, brown <=30; red above the last band",
)
#: CCFhos/CCFhol: colour by the VUT's speed reduction.
REDUCTION_BANDS = Rule(
    "2026: head-on colour by the VUT's speed reduction (km/h)",
    ((_R, 10.0), (_O, 20.0)),
    f"{RATING} matrix_processing.py (mitigation_scenarios_thresholds) reading {CAFC} "
    "Figure 5-2: up to 10 red, above 10 to 20 orange, above 20 green. The calculator's "
    "further 'red above 30' is not applied: a larger reduction cannot score less (5.2 asks "
    "a false-positive dossier above 35 km/h instead)",
    assumed=False,
    shown="<=10 red, <=20 orange, above 20 green",
)
#: FCW TTC tests (CPLA and CBLA FCW): green at a warning TTC of at least this.
FCW_TTC_S = Rule(
    "2026: FCW TTC for green (CPLA, CBLA FCW), s", 1.7, f"{CAFC} 5.2 (green >= 1.7 s)", False
)
#: Avoidance tests: green only at an impact speed of 0.
AVOIDANCE = Rule(
    "2026: avoidance tests (Vimpact 0 green, else red)",
    ("CCFtap", "CMFtap", "CCCscp", "CMCscp", "CPTA", "CBTA"),
    f"{CAFC} 5.2 (criteria table and Vimpact bands)",
    assumed=False,
)
#: Each scenario's Standard Range points (the other ranges are not scored here).
SCENARIO_POINTS = Rule(
    "2026: Standard Range points per scenario",
    {"CCRs": 1.2, "CCRm": 2.4, "CCRb": 1.6, "CCFhos": 2.0, "CCFtap": 4.0, "CCCscp": 6.0,
     "CMRs": 1.2, "CMRb": 1.6, "CMFtap": 4.0, "CMCscp": 6.0, "CPLA": 2.0, "CBLA": 2.0,
     "CPNA": 1.0, "CPFA": 1.0, "CPNCO": 2.0, "CBNA": 1.0, "CBFA": 1.0, "CBNAO": 2.0},
    f"{RATING} data_model.py TOTAL_SCORES ('Standard'; CPLA, CPNA, CPFA, CPNCO: the day and "
    "night scenarios' points added, each lighting half). CCFhol, CPTA and CBTA have no file "
    "in Vector's 2026 set; Extended Range and Robustness points are not scored",
    assumed=False,
)  # fmt: skip
RULES: tuple[Rule, ...] = (REL_BANDS, REDUCTION_BANDS, FCW_TTC_S, AVOIDANCE, SCENARIO_POINTS)


def _row(table: Mapping[int, Bands], speed_kmh: float) -> Bands:
    keys = sorted(table)
    below = [k for k in keys if k <= speed_kmh + 1e-6]
    return table[below[-1] if below else keys[0]]


def rel_colour(vut_kmh: float, contact: bool, rel_impact_kmh: float) -> Colour:
    """Colour of a mitigation-or-avoidance cell (REL_BANDS) at the VUT test speed
    ``vut_kmh``: green only without contact; else the first band whose upper limit the
    relative impact speed does not exceed (a contact at 0 km/h counts as above 0)."""
    if not contact:
        return Colour.GREEN
    v = max(rel_impact_kmh, 1e-9)
    for colour, limit in _row(_REL, vut_kmh)[1:]:
        if v <= limit + 1e-9:
            return colour
    return Colour.RED


def reduction_colour(vut_kmh: float, contact: bool, impact_kmh: float) -> Colour:
    """Colour of a head-on cell (REDUCTION_BANDS) from the VUT's speed reduction
    ``vut_kmh - impact_kmh``; avoided: the whole test speed."""
    reduction = vut_kmh - max(impact_kmh, 0.0) if contact else vut_kmh
    for colour, limit in REDUCTION_BANDS.value:  # type: ignore[attr-defined]
        if reduction <= limit + 1e-9:
            return colour
    return Colour.GREEN


def fcw_ttc_colour(warning_ttc_s: float | None) -> Colour:
    """Colour of a CPLA/CBLA FCW cell (FCW_TTC_S): green when warned at a true TTC of at least
    1.7 s; no warning is red."""
    least = float(FCW_TTC_S.value)  # type: ignore[arg-type]
    return Colour.GREEN if warning_ttc_s is not None and warning_ttc_s >= least - 1e-9 else _R


def fcw_rel_colour(
    vut_kmh: float, warning_ttc_s: float | None, contact: bool, impact_kmh: float
) -> Colour:
    """Colour of a CCRs/CMRs FCW cell on a stationary target (CA-FC 4.3.3: the robot brakes
    1.2 s after the warning at -4 m/s^2; scoring.fcw_impact_speed), judged by the relative
    impact speed like the AEB cells. The run holds the AEB alone; the lower impact counts."""
    aeb = max(impact_kmh, 0.0) if contact else 0.0
    impact = min(aeb, fcw_impact_speed(vut_kmh, warning_ttc_s))
    return rel_colour(vut_kmh, impact > 0, impact)
