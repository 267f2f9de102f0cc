"""Euro NCAP 2023 AEB scoring rules, pure (no simulation): the colour band of one test point,
its points, a scenario's and a protocol's totals.

Protocols (the README names them; ``PROTOCOLS``):

- tests: Euro NCAP Test Protocol - AEB Car-to-Car systems v4.3.1 (2023) and - AEB/LSS VRU
  systems v4.5.1 (2023), the versions Vector's OpenSCENARIO files implement; the test grids
  are the files' own Variations (bridge.studies.ncap.protocols);
- assessment: Euro NCAP Assessment Protocol - Safety Assist - Collision Avoidance (2023, C2C)
  and - Vulnerable Road User Protection v11.3 (June 2023, VRU).

The assessment protocols' texts were not available where this was written (only their titles
and tables of contents were found). Every number below that comes from neither of them is
marked ``assumed=True`` in its :class:`Rule` and in docs/guide/ncap.md; change a rule's value
here and every score follows. Speeds in km/h at this module's edge (the protocols' unit).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from enum import Enum

C2C_ASSESSMENT = "Euro NCAP Assessment Protocol - SA - Collision Avoidance (2023), AEB Car-to-Car"
VRU_ASSESSMENT = "Euro NCAP Assessment Protocol - VRU Protection v11.3 (2023), AEB VRU"
C2C_TEST = "Euro NCAP Test Protocol - AEB Car-to-Car systems v4.3.1 (2023)"
VRU_TEST = "Euro NCAP Test Protocol - AEB/LSS VRU systems v4.5.1 (2023)"
#: The documents the scores follow, by protocol.
PROTOCOLS = {"c2c": (C2C_TEST, C2C_ASSESSMENT), "vru": (VRU_TEST, VRU_ASSESSMENT)}


@dataclass(frozen=True)
class Rule:
    """One scoring rule: its value, the protocol section it follows, and whether the value is
    assumed (not found in the protocol)."""

    name: str
    value: object
    source: str
    assumed: bool


class Colour(Enum):
    """The datasheet colour of a test point, best first."""

    GREEN = "green"
    YELLOW = "yellow"
    ORANGE = "orange"
    BROWN = "brown"
    RED = "red"


#: Points fraction of each colour.
FRACTION = Rule(
    "points fraction per colour",
    {
        Colour.GREEN: 1.0,
        Colour.YELLOW: 0.75,
        Colour.ORANGE: 0.5,
        Colour.BROWN: 0.25,
        Colour.RED: 0.0,
    },
    "assessment protocols, AEB scoring: five colour bands per test point (datasheet colours)",
    assumed=True,
)
#: Lowest speed reduction (fraction of the reference speed) of each band when the target was
#: hit; a point is in the first band whose reduction it reaches (boundaries included).
REDUCTION_BANDS = Rule(
    "speed reduction per colour (impact-speed scoring)",
    ((Colour.YELLOW, 0.75), (Colour.ORANGE, 0.50), (Colour.BROWN, 0.25), (Colour.RED, 0.0)),
    "assessment protocols, AEB scoring: green only for avoidance, then bands of speed "
    "reduction relative to the test speed",
    assumed=True,
)
#: Tests scored on avoidance alone (green, or red at any contact).
AVOIDANCE_ONLY = Rule(
    "tests scored on avoidance alone",
    ("CCFtap", "CCFhos", "CCFhol", "CMFtap", "CPTA", "CPRA"),
    "assessment protocols: turn-across-path, head-on and reversing tests",
    assumed=True,
)
#: FCW test points (C2C CCRs 55-80 km/h): green when the first warning comes at a true TTC of
#: at least this many seconds, else red.
FCW_MIN_TTC_S = Rule(
    "FCW: least TTC at the first warning, s",
    2.1,
    "NHTSA FCW confirmation test, stopped lead vehicle (2.1 s), in place of the Euro NCAP "
    "number (C2C assessment, FCW), which was not found",
    assumed=True,
)
#: A test point counts only if the ego held its test speed until the test window opened.
SPEED_TOLERANCE_KMH = Rule(
    "test speed tolerance before the test window, km/h",
    1.0,
    f"{C2C_TEST} / {VRU_TEST}: test conduct, VUT speed tolerance",
    assumed=True,
)
WINDOW_TTC_S = Rule(
    "test window opens at true TTC, s",
    4.0,
    f"{C2C_TEST} / {VRU_TEST}: the test starts 4 s before the projected impact (T0)",
    assumed=True,
)
#: Weight of a test point in its scenario: each point counts the same, a scenario with day and
#: night tests counts each half.
POINT_WEIGHTS = Rule(
    "weight of a test point",
    "equal within a lighting; day and night halves",
    "assessment protocols, scenario score from the test points' points",
    assumed=True,
)

RULES: tuple[Rule, ...] = (
    FRACTION,
    REDUCTION_BANDS,
    AVOIDANCE_ONLY,
    FCW_MIN_TTC_S,
    SPEED_TOLERANCE_KMH,
    WINDOW_TTC_S,
    POINT_WEIGHTS,
)


def impact_colour(contact: bool, impact_kmh: float, reference_kmh: float) -> Colour:
    """Colour of an impact-speed test point (REDUCTION_BANDS): green when the target was not
    hit, else by the speed reduction ``1 - impact / reference`` (km/h; ``reference``: the test's
    closing speed, > 0)."""
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


def fcw_colour(warning_ttc_s: float | None) -> Colour:
    """Colour of an FCW test point from the true TTC at the first warning (None: no warning)."""
    ok = warning_ttc_s is not None and warning_ttc_s >= FCW_MIN_TTC_S.value - 1e-12  # type: ignore[operator]
    return Colour.GREEN if ok else Colour.RED


def fraction(colour: Colour) -> float:
    """Points fraction of ``colour`` (FRACTION)."""
    return FRACTION.value[colour]  # type: ignore[index]


def speed_held(speeds_kmh: Sequence[float], test_kmh: float) -> tuple[bool, float]:
    """Whether every ego speed before the test window (km/h, absolute) stays within
    SPEED_TOLERANCE_KMH of ``test_kmh``; and the speed furthest from it."""
    if not speeds_kmh:
        return True, test_kmh
    worst = max(speeds_kmh, key=lambda v: abs(abs(v) - test_kmh))
    return abs(abs(worst) - test_kmh) <= SPEED_TOLERANCE_KMH.value + 1e-9, abs(worst)  # type: ignore[operator]


@dataclass(frozen=True)
class PointScore:
    """One scored test point: its scenario, lighting ('day'/'night'), colour (None: not
    tested) and why it was not tested."""

    scenario: str
    lighting: str
    colour: Colour | None
    not_tested: str = ""

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
    """``max_points`` times the weighted mean fraction of the scenario's points (POINT_WEIGHTS:
    equal weight within a lighting, each lighting present the same share). Points not tested
    count as zero: the protocol scores a test it could not run as failed."""
    pts = [p for p in points if p.scenario == scenario]
    lightings = sorted({p.lighting for p in pts})
    if not pts:
        return ScenarioScore(scenario, 0.0, max_points, 0, 0)
    share = 0.0
    for light in lightings:
        group = [p.points_fraction for p in pts if p.lighting == light]
        share += sum(group) / len(group) / len(lightings)
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
    """The sum of the scenarios' weighted totals."""
    sc = tuple(scenarios)
    return ProtocolScore(protocol, sum(s.points for s in sc), sum(s.max_points for s in sc), sc)
