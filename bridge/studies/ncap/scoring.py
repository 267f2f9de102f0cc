"""Euro NCAP 2023 AEB scoring rules, pure (no simulation): the colour band of one test point,
its weight, a scenario's and a protocol's totals.

Protocols (the README names them; ``PROTOCOLS``):

- tests: Euro NCAP Test Protocol - AEB Car-to-Car systems v4.3.1 (Implementation 2023,
  February 2024) and - AEB/LSS VRU systems v4.5.1 (2023), the versions Vector's OpenSCENARIO
  files implement; the test grids are the files' own Variations
  (bridge.studies.ncap.protocols);
- assessment: Euro NCAP Assessment Protocol - Safety Assist - Collision Avoidance v10.4.1
  (Implementation 2023, February 2024; section 3, AEB Car-to-Car) and - Vulnerable Road User
  Protection v11.3 (June 2023; AEB VRU).

Where the numbers come from (docs/guide/ncap.md has the table):

- the Car-to-Car rules were read in the text of SA Collision Avoidance v10.4.1 (``SA``, the
  PDF at ``SA_URL``) and of the C2C test protocol v4.3.1 (``C2C``, ``C2C_URL``): colour
  fractions, the 50 km/h colour band example, points per test speed, overlap weights, scenario
  points, CCFtap, head-on and FCW criteria, test window and speed tolerance. They are marked
  ``assumed=False``.
- the protocol draws the CCR colour bands of the other test speeds as a figure, whose values
  are not in its text. Those values are BeamNG's reading of the same figure in SA v9.1
  (``BEAMNG``); the one row the text gives (50 km/h) agrees with it. They stay
  ``assumed=True``.
- the text of the VRU assessment protocol v11.3 past its introduction was not found: every
  VRU number stays ``assumed=True``.

Change a rule's value here and every score follows. Speeds in km/h at this module's edge (the
protocols' unit), times in s, decelerations in m/s^2.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from enum import Enum

C2C_ASSESSMENT = (
    "Euro NCAP Assessment Protocol - SA - Collision Avoidance v10.4.1 (2023), AEB Car-to-Car"
)
VRU_ASSESSMENT = "Euro NCAP Assessment Protocol - VRU Protection v11.3 (2023), AEB VRU"
C2C_TEST = "Euro NCAP Test Protocol - AEB Car-to-Car systems v4.3.1 (2023)"
VRU_TEST = "Euro NCAP Test Protocol - AEB/LSS VRU systems v4.5.1 (2023)"
#: The documents the scores follow, by protocol.
PROTOCOLS = {"c2c": (C2C_TEST, C2C_ASSESSMENT), "vru": (VRU_TEST, VRU_ASSESSMENT)}

SA = "SA Collision Avoidance v10.4.1"
SA_URL = (
    "https://cdn.euroncap.com/cars/assets/"
    "euro_ncap_assessment_protocol_sa_collision_avoidance_v1041_fafe1dd418.pdf"
)
C2C = "AEB C2C test protocol v4.3.1"
C2C_URL = "https://cdn.euroncap.com/cars/assets/euro_ncap_aeb_c2c_test_protocol_v431_532926aad1.pdf"
BEAMNG = (
    "BeamNG/BeamNG_NCAP_Tests src/beamng_ncap/scenarios.py (CCRS/CCRM._get_color_scheme), "
    "a reading of the colour figure of SA v9.1 (2021)"
)


@dataclass(frozen=True)
class Rule:
    """One scoring rule: its value, the protocol section it follows, and whether the value is
    assumed (not found in the protocol's text). ``shown``: the value as the report prints it
    ('' prints ``value``)."""

    name: str
    value: object
    source: str
    assumed: bool
    shown: str = ""


class Colour(Enum):
    """The datasheet colour of a test point, best first."""

    GREEN = "green"
    YELLOW = "yellow"
    ORANGE = "orange"
    BROWN = "brown"
    RED = "red"


_G, _Y, _O, _B, _R = Colour.GREEN, Colour.YELLOW, Colour.ORANGE, Colour.BROWN, Colour.RED
#: An impact-speed band table: (colour, least impact speed of the next band, km/h), best
#: first; an impact at or above the last limit is red. Lower limit included, upper excluded.
Bands = tuple[tuple[Colour, float], ...]

#: Points fraction of each colour.
FRACTION = Rule(
    "points fraction per colour",
    {_G: 1.0, _Y: 0.75, _O: 0.5, _B: 0.25, _R: 0.0},
    f"{SA} 3.3.2 (scaling per predicted colour). VRU: the same fractions assumed",
    assumed=False,
)


def _table(bands: Mapping[int, Bands]) -> str:
    """A band table as the report prints it: 'speed: green <5, yellow <15, ...'."""
    return "; ".join(
        f"{v}: " + ", ".join(f"{c.value} <{lim:g}" for c, lim in b) for v, b in bands.items()
    )


#: CCRs and CCRb colour by the impact speed (Vimpact) at 50 km/h: the row the text gives.
CCR_BANDS_50 = Rule(
    "CCRs/CCRb colour at a 50 km/h test speed, by impact speed",
    ((_G, 5.0), (_Y, 15.0), (_O, 30.0), (_B, 40.0)),
    f"{SA} 3.3.2 (table of the speed range of each colour at 50 km/h; CCRb counts as a CCRs "
    "test at 50 km/h) and 3.3.2.2",
    assumed=False,
    shown="green <5, yellow <15, orange <30, brown <40, red from 40 km/h",
)
_CCRS: dict[int, Bands] = {
    10: ((_G, 1.0),),
    15: ((_G, 1.0),),
    20: ((_G, 1.0),),
    25: ((_G, 5.0), (_O, 15.0)),
    30: ((_G, 5.0), (_Y, 15.0), (_O, 25.0)),
    35: ((_G, 5.0), (_Y, 15.0), (_O, 25.0)),
    40: ((_G, 5.0), (_Y, 15.0), (_O, 25.0), (_B, 35.0)),
    45: ((_G, 5.0), (_Y, 15.0), (_O, 25.0), (_B, 35.0)),
    50: CCR_BANDS_50.value,  # type: ignore[dict-item]
}
_CCRM: dict[int, Bands] = {
    30: ((_G, 5.0),),
    35: ((_G, 5.0),),
    40: ((_G, 5.0), (_O, 15.0)),
    45: ((_G, 5.0), (_O, 15.0)),
    50: ((_G, 5.0), (_Y, 15.0), (_O, 25.0)),
    55: ((_G, 5.0), (_Y, 15.0), (_O, 25.0)),
    60: ((_G, 5.0), (_Y, 15.0), (_O, 25.0), (_B, 35.0)),
    65: ((_G, 5.0), (_Y, 15.0), (_O, 25.0), (_B, 35.0)),
    70: ((_G, 5.0), (_Y, 15.0), (_O, 30.0), (_B, 40.0)),
    75: ((_G, 5.0), (_Y, 15.0), (_O, 30.0), (_B, 45.0)),
    80: ((_G, 5.0), (_Y, 20.0), (_O, 35.0), (_B, 50.0)),
}
#: CCRs colour by the impact speed at each test speed (10-50 km/h, the AEB grid).
CCRS_BANDS = Rule(
    "CCRs colour by impact speed, per test speed (km/h)",
    _CCRS,
    f"{SA} 3.3.2 draws these bands as a figure (CCRs and CCRb, impact speed) without numbers; "
    f"values from {BEAMNG}. Its 50 km/h row equals the text's table (CCR_BANDS_50)",
    assumed=True,
    shown=_table(_CCRS),
)
#: CCRm colour by the relative impact speed (Vrel_impact) at each test speed of the VUT.
CCRM_BANDS = Rule(
    "CCRm colour by relative impact speed, per VUT test speed (km/h)",
    _CCRM,
    f"{SA} 3.3.2 draws these bands as a figure (CCRm, relative impact speed; its top row "
    f"'130 & 80 km/h') without numbers; values from {BEAMNG}",
    assumed=True,
    shown=_table(_CCRM),
)
#: CCRs above 50 km/h (the FCW grid, 55-80 km/h): the CCRm row of the same closing speed.
CCRS_HIGH_SPEED = Rule(
    "CCRs colour above 50 km/h (FCW tests)",
    "the CCRm row with the same closing speed (VUT speed + 20 km/h), the 80 km/h row beyond",
    f"{SA} 3.3.2 figure runs to 80 km/h for CCRs; no reading of its rows above 50 km/h was "
    "found. Where both are known (25-50 km/h closing speed) the CCRs and CCRm rows of equal "
    "closing speed are equal, hence this assumption",
    assumed=True,
)
#: Which speed each CCR test is judged by.
CCR_CRITERION = Rule(
    "CCR assessment criterion",
    "CCRs (AEB and FCW) and CCRb: impact speed of the VUT; CCRm: relative impact speed",
    f"{SA} 3.3.1",
    assumed=False,
)
#: Points of each test speed in a CCR scenario (sum over a speed's overlaps, below).
CCRS_SPEED_POINTS = Rule(
    "CCRs (AEB) points per test speed",
    {10: 1.0, 15: 2.0, 20: 2.0, 25: 2.0, 30: 2.0, 35: 2.0, 40: 1.0, 45: 1.0, 50: 1.0},
    f"{SA} 3.3.2 (points table, total 14)",
    assumed=False,
)
CCRM_SPEED_POINTS = Rule(
    "CCRm points per test speed",
    {v: 1.0 for v in range(30, 65, 5)} | {v: 2.0 for v in range(65, 85, 5)},
    f"{SA} 3.3.2 (points table, total 15)",
    assumed=False,
)
FCW_SPEED_POINTS = Rule(
    "CCRs FCW points per test speed",
    {v: 1.0 for v in range(55, 85, 5)},
    f"{SA} 3.3.2 (points table, total 6)",
    assumed=False,
)
#: Weight of each overlap in a test speed's score: 100 % counts twice, of 6.
OVERLAP_WEIGHTS = Rule(
    "CCRs/CCRm overlap weights within a test speed",
    {-50: 1.0, -75: 1.0, 100: 2.0, 75: 1.0, 50: 1.0},
    f"{SA} 3.3.2 (score per test speed = (s[-50%] + s[-75%] + 2 s[100%] + s[75%] + s[50%]) / 6)",
    assumed=False,
)
#: CCRs scores nothing unless every point up to 20 km/h is avoided.
CCRS_AVOIDANCE_UP_TO_KMH = Rule(
    "CCRs precondition: full avoidance up to this test speed, km/h",
    20.0,
    f"{SA} 3.3 (CCRs points only with full avoidance up to and including 20 km/h, all "
    "overlaps). The other preconditions (whiplash rating, CCRm 130 km/h evidence, system "
    "default on) are outside a simulation and not applied",
    assumed=False,
)
#: Head-on tests: points by the speed reduction of the VUT.
HEADON_REDUCTION_KMH = Rule(
    "CCFhos/CCFhol: speed reduction for full / half points, km/h",
    (20.0, 10.0),
    f"{SA} 3.3.5 (0.25 points per test at a reduction of at least 20 km/h, 0.125 from 10 "
    "km/h; the OEM's dossier is assessed, tests optional). Full is green, half is orange "
    "(fraction 0.5)",
    assumed=False,
)
#: Tests scored on avoidance alone (green, or red at any contact).
AVOIDANCE_ONLY = Rule(
    "tests scored on avoidance alone",
    ("CCFtap", "CMFtap", "CPTA", "CPRA"),
    f"CCFtap: {SA} 3.3.1 and 3.3.3 (normalised count of the 9 tests avoided). CMFtap, CPTA, "
    "CPRA: VRU assessment v11.3 not found",
    assumed=True,
)
#: VRU impact-speed tests: bands of speed reduction relative to the test speed.
REDUCTION_BANDS = Rule(
    "VRU colour by speed reduction (impact-speed tests)",
    ((Colour.YELLOW, 0.75), (Colour.ORANGE, 0.50), (Colour.BROWN, 0.25), (Colour.RED, 0.0)),
    "VRU assessment v11.3 (AEB VRU scoring) not found: green only for avoidance, then bands "
    "of speed reduction relative to the reference speed, boundary in the better band",
    assumed=True,
)
#: FCW test (CCRs 55-80 km/h): a robot brakes this long after the warning.
FCW_REACTION_S = Rule(
    "FCW test: driver (robot) reaction after the warning, s",
    1.2,
    f"{C2C} 8.4.6 and Annex A.4 (brake pedal from TFCW + 1.2 s, reaching its level within "
    f"0.2 s); {SA} 3.3.1 (FCW tests judged by the impact speed)",
    assumed=False,
)
FCW_DECELERATION = Rule(
    "FCW test: the robot's braking, m/s^2; pedal ramp, s",
    (4.0, 0.2),
    f"{C2C} 8.4.6.1 (-4 m/s^2, tolerance -0.5: the least braking is used) and A.4 (200 ms "
    "pedal ramp, taken as a linear rise of the deceleration)",
    assumed=False,
)
#: A test point counts only if the ego held its test speed until the test window opened.
SPEED_TOLERANCE_KMH = Rule(
    "VUT speed tolerance (below, above the test speed), km/h",
    (0.0, 1.0),
    f"{C2C} 8.4.2 (VUT speed: test speed +1.0 km/h between T0 and the first intervention). "
    "VRU: the same assumed (VRU test protocol text not found)",
    assumed=False,
)
SPEED_ACCURACY_KMH = Rule(
    "speed measuring accuracy, km/h (slack on the tolerance)",
    0.1,
    f"{C2C} 4.2.1 (speeds recorded to 0.1 km/h)",
    assumed=False,
)
WINDOW_TTC_S = Rule(
    "test window opens at true TTC, s",
    4.0,
    f"{C2C} 4.1.1 (T0 = TTC 4 s unless stated; hiyari applies it to every test, also where "
    "the protocol starts the window 1 s before the turn (CCFtap) or before the target brakes "
    "(CCRb)). VRU: the same assumed",
    assumed=False,
)
#: Scenario points of the C2C tests hiyari runs (SA 3.3.2-3.3.5).
C2C_POINTS = Rule(
    "C2C scenario points",
    {"CCRs": 1.0, "CCRs-FCW": 0.5, "CCRm": 1.0, "CCRb": 1.0, "CCFtap": 1.0, "CCFhos": 0.5,
     "CCFhol": 0.5},
    f"{SA} 3.3.2 (CCR 3.5: CCRs, CCRm, CCRb 1 each, CCRs FCW 0.5), 3.3.3 (CCFtap 1), 3.3.5 "
    "(head-on 1: 0.25 per test, two tests each in CCFhos and CCFhol)",
    assumed=False,
)  # fmt: skip
C2C_PROTOCOL_POINTS = Rule(
    "AEB Car-to-Car total in Safety Assist, points",
    9.0,
    f"{SA} 3.3.7: hiyari runs 5.5 of them; CCCscp AEB (2) and FCW (1) have no file in "
    "Vector's set, HMI (0.5) is not a driving test",
    assumed=False,
)
#: Weight of a VRU test point in its scenario.
POINT_WEIGHTS = Rule(
    "VRU weight of a test point",
    "equal within a lighting; day and night halves",
    "VRU assessment v11.3 (scenario score) not found",
    assumed=True,
)

RULES: tuple[Rule, ...] = (
    FRACTION,
    CCR_BANDS_50,
    CCRS_BANDS,
    CCRM_BANDS,
    CCRS_HIGH_SPEED,
    CCR_CRITERION,
    CCRS_SPEED_POINTS,
    CCRM_SPEED_POINTS,
    FCW_SPEED_POINTS,
    OVERLAP_WEIGHTS,
    CCRS_AVOIDANCE_UP_TO_KMH,
    HEADON_REDUCTION_KMH,
    AVOIDANCE_ONLY,
    REDUCTION_BANDS,
    FCW_REACTION_S,
    FCW_DECELERATION,
    SPEED_TOLERANCE_KMH,
    SPEED_ACCURACY_KMH,
    WINDOW_TTC_S,
    C2C_POINTS,
    C2C_PROTOCOL_POINTS,
    POINT_WEIGHTS,
)


def _row(table: Mapping[int, object], speed_kmh: float) -> int:
    """The tabulated speed of ``speed_kmh``: the highest one not above it (the lowest when
    below the table; the top row for faster tests, e.g. CCRm's '130 & 80 km/h')."""
    keys = sorted(table)
    below = [k for k in keys if k <= speed_kmh + 1e-6]
    return below[-1] if below else keys[0]


def band_colour(bands: Bands, impact_kmh: float) -> Colour:
    """Colour of an impact speed (km/h) in a band table: the first band whose limit it stays
    under; red at or above the last limit."""
    for colour, limit in bands:
        if impact_kmh < limit:
            return colour
    return Colour.RED


def ccr_bands(test: str, speed_kmh: float) -> Bands:
    """The colour bands of a CCR test ('CCRs', 'CCRs-FCW', 'CCRm', 'CCRb') at the VUT test
    speed ``speed_kmh`` (CCRb: always the CCRs 50 km/h row)."""
    if test == "CCRb":
        return CCR_BANDS_50.value  # type: ignore[return-value]
    if test == "CCRm":
        return _CCRM[_row(_CCRM, speed_kmh)]
    if test not in ("CCRs", "CCRs-FCW"):
        raise ValueError(f"{test}: not a Car-to-Car Rear test")
    if speed_kmh <= 50 + 1e-6:
        return _CCRS[_row(_CCRS, speed_kmh)]
    return _CCRM[_row(_CCRM, speed_kmh + 20.0)]  # CCRS_HIGH_SPEED


def ccr_colour(test: str, speed_kmh: float, contact: bool, impact_kmh: float) -> Colour:
    """Colour of a CCR test point: ``impact_kmh`` is the VUT's impact speed (CCRs, CCRb) or
    the relative impact speed (CCRm), km/h; no contact is an impact at 0 km/h."""
    return band_colour(ccr_bands(test, speed_kmh), max(impact_kmh, 0.0) if contact else 0.0)


def headon_colour(test_kmh: float, contact: bool, impact_kmh: float) -> Colour:
    """Colour of a CCFhos/CCFhol test (HEADON_REDUCTION_KMH) from the VUT's speed reduction
    ``test_kmh - impact_kmh`` (km/h); avoided: the whole test speed. Green: full points,
    orange: half, red: none."""
    full, half = HEADON_REDUCTION_KMH.value  # type: ignore[misc]
    reduction = test_kmh - max(impact_kmh, 0.0) if contact else test_kmh
    if reduction >= full - 1e-9:
        return Colour.GREEN
    return Colour.ORANGE if reduction >= half - 1e-9 else Colour.RED


def fcw_impact_speed(test_kmh: float, warning_ttc_s: float | None) -> float:
    """Impact speed (km/h) of the FCW test on a stationary target: the VUT at ``test_kmh``
    warned at a true TTC of ``warning_ttc_s`` (None: no warning, no braking) is braked by the
    robot from FCW_REACTION_S after the warning, its deceleration rising linearly to
    FCW_DECELERATION over the pedal ramp, then held. 0 when it stops short."""
    v = test_kmh / 3.6
    if warning_ttc_s is None or v <= 0:
        return test_kmh
    reaction = float(FCW_REACTION_S.value)  # type: ignore[arg-type]
    decel, ramp = FCW_DECELERATION.value  # type: ignore[misc]
    gap = v * warning_ttc_s - v * reaction  # left when the pedal starts moving, m
    if gap <= 0:
        return test_kmh
    jerk = decel / ramp
    x_ramp = v * ramp - jerk * ramp**3 / 6.0
    if x_ramp >= gap:  # contact during the ramp: v t - j t^3 / 6 = gap, by bisection
        lo, hi = 0.0, ramp
        for _ in range(60):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if v * mid - jerk * mid**3 / 6.0 < gap else (lo, mid)
        return max(v - jerk * lo**2 / 2.0, 0.0) * 3.6
    v_ramp = v - decel * ramp / 2.0
    left = v_ramp**2 - 2.0 * decel * (gap - x_ramp)
    return math.sqrt(left) * 3.6 if left > 0 else 0.0


def fcw_colour(
    test_kmh: float, warning_ttc_s: float | None, contact: bool, impact_kmh: float
) -> tuple[Colour, float]:
    """Colour of an FCW test point (CCRs 55-80 km/h, judged by the impact speed as a CCRs
    test) and the impact speed it is judged by (km/h). The run holds the AEB alone; the
    robot's braking after the warning is modelled (fcw_impact_speed). Both brake in the real
    test, so the lower of the two impact speeds counts: an upper bound of the combined one."""
    aeb = max(impact_kmh, 0.0) if contact else 0.0
    impact = min(aeb, fcw_impact_speed(test_kmh, warning_ttc_s))
    return ccr_colour("CCRs-FCW", test_kmh, impact > 0, impact), impact


def impact_colour(contact: bool, impact_kmh: float, reference_kmh: float) -> Colour:
    """Colour of a VRU impact-speed test point (REDUCTION_BANDS): green when the target was
    not hit, else by the speed reduction ``1 - impact / reference`` (km/h; ``reference``: the
    test's closing speed, > 0)."""
    if not contact:
        return Colour.GREEN
    if reference_kmh <= 0:
        raise ValueError(f"reference speed must be positive, got {reference_kmh} km/h")
    reduction = 1.0 - max(impact_kmh, 0.0) / reference_kmh
    for colour, least in REDUCTION_BANDS.value:  # type: ignore[attr-defined]
        if reduction >= least - 1e-12:
            return colour
    return Colour.RED


def avoidance_colour(contact: bool) -> Colour:
    """Colour of a test scored on avoidance alone (AVOIDANCE_ONLY)."""
    return Colour.RED if contact else Colour.GREEN


def fraction(colour: Colour) -> float:
    """Points fraction of ``colour`` (FRACTION)."""
    return FRACTION.value[colour]  # type: ignore[index]


def point_weight(test: str, speed_kmh: float | None, overlap: float | None) -> float:
    """Weight of a test point in its scenario, in the scenario's points-table units: for CCRs,
    CCRs-FCW and CCRm the points of its test speed times its overlap's share of 6
    (OVERLAP_WEIGHTS, 100 % double); every other test point 1 (equal weights: CCRb, CCFtap,
    head-on by the protocol, VRU assumed). A speed missing from the table weighs 1."""
    tables = {"CCRs": CCRS_SPEED_POINTS, "CCRs-FCW": FCW_SPEED_POINTS, "CCRm": CCRM_SPEED_POINTS}
    if test not in tables or speed_kmh is None:
        return 1.0
    points = tables[test].value.get(int(round(speed_kmh)), 1.0)  # type: ignore[attr-defined]
    weights: dict[int, float] = OVERLAP_WEIGHTS.value  # type: ignore[assignment]
    if overlap is None:
        return points
    share = weights.get(int(round(overlap)), 1.0) / sum(weights.values())
    return points * share


def speed_held(speeds_kmh: Sequence[float], test_kmh: float) -> tuple[bool, float]:
    """Whether every ego speed before the test window (km/h, absolute) stays within
    SPEED_TOLERANCE_KMH of ``test_kmh`` (widened by SPEED_ACCURACY_KMH); and the speed
    furthest from it."""
    if not speeds_kmh:
        return True, test_kmh
    below, above = SPEED_TOLERANCE_KMH.value  # type: ignore[misc]
    slack = float(SPEED_ACCURACY_KMH.value) + 1e-9  # type: ignore[arg-type]
    worst = max(speeds_kmh, key=lambda v: abs(abs(v) - test_kmh))
    ok = all(test_kmh - below - slack <= abs(v) <= test_kmh + above + slack for v in speeds_kmh)
    return ok, abs(worst)


@dataclass(frozen=True)
class PointScore:
    """One scored test point: its scenario, lighting ('day'/'night'), colour (None: not
    tested) and why it was not tested; its ``weight`` in the scenario (point_weight);
    ``voids_scenario``: the point breaks a precondition that zeroes its scenario
    (CCRS_AVOIDANCE_UP_TO_KMH)."""

    scenario: str
    lighting: str
    colour: Colour | None
    not_tested: str = ""
    weight: float = 1.0
    voids_scenario: bool = False

    @property
    def points_fraction(self) -> float:
        """0..1; a point not tested scores nothing."""
        return 0.0 if self.colour is None else fraction(self.colour)


@dataclass(frozen=True)
class ScenarioScore:
    """A scenario's total: ``points`` of ``max_points``; counts of points tested and not."""

    scenario: str
    points: float
    max_points: float
    tested: int
    not_tested: int


def scenario_score(scenario: str, max_points: float, points: Iterable[PointScore]) -> ScenarioScore:
    """``max_points`` times the weighted mean fraction of the scenario's points: within a
    lighting each point counts its ``weight`` (the protocol's points-table normalisation,
    SA 3.3.2: points scored over points available), each lighting present the same share
    (POINT_WEIGHTS, assumed). Points not tested count as zero: the protocol scores a test it
    could not run as failed. A point with ``voids_scenario`` zeroes the scenario."""
    pts = [p for p in points if p.scenario == scenario]
    lightings = sorted({p.lighting for p in pts})
    if not pts:
        return ScenarioScore(scenario, 0.0, max_points, 0, 0)
    share = 0.0
    for light in lightings:
        group = [p for p in pts if p.lighting == light]
        total = sum(p.weight for p in group)
        if total > 0:
            share += sum(p.weight * p.points_fraction for p in group) / total / len(lightings)
    if any(p.voids_scenario for p in pts):
        share = 0.0
    tested = sum(p.colour is not None for p in pts)
    return ScenarioScore(scenario, max_points * share, max_points, tested, len(pts) - tested)


@dataclass(frozen=True)
class ProtocolScore:
    """A protocol's total and its scenarios."""

    protocol: str
    points: float
    max_points: float
    scenarios: tuple[ScenarioScore, ...]

    @property
    def percent(self) -> float:
        """Points as a percentage of the maximum."""
        return 100.0 * self.points / self.max_points if self.max_points else 0.0


def protocol_score(protocol: str, scenarios: Iterable[ScenarioScore]) -> ProtocolScore:
    """The sum of the scenarios' weighted totals (SA 3.3.7: the AEB C2C total is the weighted
    sum of its scenario scores)."""
    sc = tuple(scenarios)
    return ProtocolScore(protocol, sum(s.points for s in sc), sum(s.max_points for s in sc), sc)
