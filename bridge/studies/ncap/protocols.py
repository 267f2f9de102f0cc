"""The Euro NCAP 2023 AEB tests that ``hiyari ncap`` runs: for each test its Variations file
in Vector's OSC-NCAP-scenarios set, the grid's axes as the datasheet draws them (test speed x
overlap, impact position, target speed...), how it is scored, its lightings and its points.

The grids are the Variations files' own distributions (nothing is re-declared here): a test's
runs are exactly the file's runs. The C2C scenario points and lightings follow the Safety
Assist - Collision Avoidance assessment protocol v10.4.1 (sections 3.3.2-3.3.5; its tests are
daylight tests, AEB C2C test protocol v4.3.1 section 7.2.3); the VRU ones are assumed (see
bridge.studies.ncap.scoring): the VRU assessment protocol's point tables were not found.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from hiyari.bridge.studies.ncap.scoring2026 import SCENARIO_POINTS
from hiyari.checkout import shared_dir
from hiyari.errors import HiyariError

#: Environment variable naming the root of the Euro NCAP set (the folder holding OpenSCENARIO/).
ENV_DIR = "HIYARI_NCAP_DIR"
#: The 2023 protocols, the ones 'all' runs (the files in the shared set).
PROTOCOL_NAMES = ("c2c", "vru")
#: The 2026 Crash Avoidance - Frontal Collisions protocol: Vector's CA-FC_2026 folder, not in
#: the shared set (--files names a checkout holding it).
CA2026 = "ca2026"


@dataclass(frozen=True)
class NcapTest:
    """One test of a protocol.

    ``file``: its Variations file under OpenSCENARIO/NCAP. ``row`` / ``col``: the parameters
    of the datasheet grid's rows (the test speed) and columns (None: one column).
    ``scoring``: "ccr" (CCR colour bands by impact speed per test speed), "fcw" (CCRs FCW:
    impact speed with the robot braking after the warning), "headon" (speed reduction),
    "avoidance" or "impact" (VRU: colour by speed reduction, assumed).
    ``target_speed``: the parameter whose value (km/h) the target moves at along the ego's
    path; the reference speed of the impact bands is the ego's test speed minus it.
    ``lightings``: ("day",) or ("day", "night"); ``night_assumed``: the night test is not
    confirmed by a source. ``max_points``: the scenario's points; ``points_assumed``: not
    found in the assessment protocol (scoring.C2C_POINTS has the C2C ones' source)."""

    key: str
    protocol: str
    title: str
    file: str
    row: str
    col: str | None
    scoring: str
    max_points: float
    target_speed: str | None = None
    lightings: tuple[str, ...] = ("day",)
    night_assumed: bool = True
    points_assumed: bool = True
    #: the scenario the test's points count in (the 2026 FCW grids share their AEB
    #: scenario's points); '' is the test's own key
    scenario: str = ""
    #: a second column parameter: the grid's columns are its pairs with ``col`` (the 2026
    #: crossing grids run each speed pair from both sides)
    col2: str | None = None
    #: the run parameter naming the lighting ('Sunny' day, 'Night' night) when the file's
    #: own grid holds both (2026); None: hiyari runs each lighting of ``lightings``
    lighting_param: str | None = None

    @property
    def scenario_key(self) -> str:
        """The scenario whose points the test's points count in."""
        return self.scenario or self.key

    @property
    def relative(self) -> bool:
        """Whether the point is judged by the relative impact speed (CCRm, and the VRU
        longitudinal tests: the target moves along the ego's path) rather than the ego's
        impact speed (CCRs and CCRb: Vimpact, SA Collision Avoidance v10.4.1 3.3.1)."""
        if self.key == "CCRm":
            return True
        return self.protocol in ("vru", CA2026) and self.target_speed is not None


_C = "AEB_C2C_2023/Variations/NCAP_AEB_C2C_"
_V = "AEB_VRU_2023/Variations/NCAP_AEB_VRU_"
DN = ("day", "night")

#: Every test, in datasheet order.
TESTS: tuple[NcapTest, ...] = (
    NcapTest("CCRs", "c2c", "Car-to-Car Rear stationary", f"{_C}CCRs_Variation_2023.xosc",
             "Ego_speed_kph", "Overlap", "ccr", 1.0, "GVT_init_speed_kph", points_assumed=False),
    NcapTest("CCRs-FCW", "c2c", "Car-to-Car Rear stationary, FCW",
             f"{_C}CCRs_FCW_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "fcw", 0.5,
             points_assumed=False),
    NcapTest("CCRm", "c2c", "Car-to-Car Rear moving", f"{_C}CCRm_Variation_2023.xosc",
             "Ego_speed_kph", "Overlap", "ccr", 1.0, "GVT_init_speed_kph", points_assumed=False),
    NcapTest("CCRb", "c2c", "Car-to-Car Rear braking", f"{_C}CCRb_Variation_2023.xosc",
             "GVT_headway", "GVT_deceleration", "ccr", 1.0, points_assumed=False),
    NcapTest("CCFtap", "c2c", "Car-to-Car Front turn-across-path",
             f"{_C}CCFtap_Variation_2023.xosc", "Ego_speed_kph", "Target_finalSpeed_kph",
             "avoidance", 1.0, points_assumed=False),
    NcapTest("CCFhos", "c2c", "Car-to-Car Front head-on straight",
             f"{_C}CCFhos_Variation_2023.xosc", "Ego_speed_kph", None, "headon", 0.5,
             points_assumed=False),
    NcapTest("CCFhol", "c2c", "Car-to-Car Front head-on lane change",
             f"{_C}CCFhol_Variation_2023.xosc", "Ego_speed_kph", None, "headon", 0.5,
             points_assumed=False),
    NcapTest("CPNA-25", "vru", "Pedestrian Nearside Adult 25 %",
             f"{_V}CPNA-25_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "impact", 1.0,
             lightings=DN),
    NcapTest("CPNA-75", "vru", "Pedestrian Nearside Adult 75 %",
             f"{_V}CPNA-75_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "impact", 1.0,
             lightings=DN),
    NcapTest("CPFA-50", "vru", "Pedestrian Farside Adult 50 %",
             f"{_V}CPFA-50_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "impact", 1.0,
             lightings=DN),
    # MathWorks' ncapSpec("VRU AEB Crossing CPNCO") lists Day and Night variations
    NcapTest("CPNCO-50", "vru", "Pedestrian Nearside Child Obstructed 50 %",
             f"{_V}CPNCO-50_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "impact", 1.0,
             lightings=DN, night_assumed=False),
    NcapTest("CPLA-25", "vru", "Pedestrian Longitudinal Adult 25 %",
             f"{_V}CPLA-25_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "impact", 0.5,
             "VRU_finalSpeed_kph", lightings=DN),
    NcapTest("CPLA-50", "vru", "Pedestrian Longitudinal Adult 50 %",
             f"{_V}CPLA-50_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "impact", 0.5,
             "VRU_finalSpeed_kph"),
    NcapTest("CPTAfo-50", "vru", "Pedestrian Turning Adult, farside opposite",
             f"{_V}CPTAfo-50_Variation_2023.xosc", "Ego_speed_kph", None, "avoidance", 0.5),
    NcapTest("CPTAfs-50", "vru", "Pedestrian Turning Adult, farside same direction",
             f"{_V}CPTAfs-50_Variation_2023.xosc", "Ego_speed_kph", None, "avoidance", 0.5),
    # the set has no Variations file for the nearside turns: their one concrete run each
    NcapTest("CPTAno-50", "vru", "Pedestrian Turning Adult, nearside opposite",
             f"{_V}CPTAno-50_10kph_2023.xosc", "Ego_speed_kph", None, "avoidance", 0.25),
    NcapTest("CPTAns-50", "vru", "Pedestrian Turning Adult, nearside same direction",
             f"{_V}CPTAns-50_10kph_2023.xosc", "Ego_speed_kph", None, "avoidance", 0.25),
    NcapTest("CPRA-Cm", "vru", "Pedestrian Reverse Adult/Child moving",
             f"{_V}CPRA_Cm_Variation_2023.xosc", "Ego_speed_kph", "VRU_catalogEntry",
             "avoidance", 0.5),
    NcapTest("CPRA-Cs", "vru", "Pedestrian Reverse Adult/Child stationary",
             f"{_V}CPRA_Cs_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "avoidance", 0.5),
    NcapTest("CBNA-50", "vru", "Bicyclist Nearside Adult 50 %",
             f"{_V}CBNA-50_Variation_2023.xosc", "Ego_speed_kph", None, "impact", 1.0),
    NcapTest("CBNAO-50", "vru", "Bicyclist Nearside Adult Obstructed 50 %",
             f"{_V}CBNAO-50_Variation_2023.xosc", "Ego_speed_kph", None, "impact", 1.0),
    NcapTest("CBFA-50", "vru", "Bicyclist Farside Adult 50 %",
             f"{_V}CBFA-50_Variation_2023.xosc", "Ego_speed_kph", None, "impact", 1.0),
    NcapTest("CBLA-25", "vru", "Bicyclist Longitudinal Adult 25 %",
             f"{_V}CBLA-25_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "impact", 1.0,
             "VRU_finalSpeed_kph"),
    NcapTest("CBLA-50", "vru", "Bicyclist Longitudinal Adult 50 %",
             f"{_V}CBLA-50_Variation_2023.xosc", "Ego_speed_kph", "Overlap", "impact", 1.0,
             "VRU_finalSpeed_kph"),
    NcapTest("CMFtap", "vru", "Motorcyclist Front turn-across-path",
             f"{_V}CMFtap_Variation_2023.xosc", "Ego_speed_kph", "Target_finalSpeed_kph",
             "avoidance", 1.0),
)  # fmt: skip


_F = "CA-FC_2026/Variations/StandardRange/"
_P26 = {"points_assumed": False}
_DN26 = {"lightings": DN, "night_assumed": False, "lighting_param": "LightingConditions"}
_IL = "ImpactLocation"
_SPEED = "Ego_speed_kph"


def _t26(key: str, title: str, file: str, col: str | None, scoring: str, **kw: object) -> NcapTest:
    """A 2026 test; its points are its scenario's (scoring2026.SCENARIO_POINTS), a test that
    counts in another's scenario (``scenario``) adds none."""
    points = 0.0 if kw.get("scenario") else float(SCENARIO_POINTS.value[key])  # type: ignore[index]
    return NcapTest(
        key, CA2026, title, f"{_F}{file}.xosc", _SPEED, col, scoring, points, **{**_P26, **kw}
    )  # type: ignore[arg-type]


#: The 2026 CA-FC Standard Range tests of Vector's set, in datasheet order. Points:
#: scoring2026.SCENARIO_POINTS. Scoring: "rel26" (relative impact speed bands), "fcw26"
#: (CCRs/CMRs FCW: the robot brakes after the warning), "fcwttc26" (CPLA/CBLA FCW: warning
#: TTC), "headon26" (speed reduction), "avoidance" (no contact).
TESTS_2026: tuple[NcapTest, ...] = (
    _t26("CCRs", "Car-to-Car Rear stationary (AEB)", "CCRs", _IL, "rel26"),
    _t26("CCRs-FCW", "Car-to-Car Rear stationary (FCW)", "CCRs_FCW", _IL, "fcw26",
         scenario="CCRs"),
    _t26("CCRm", "Car-to-Car Rear moving", "CCRm", _IL, "rel26",
         target_speed="Target_init_speed_kph"),
    _t26("CCRb", "Car-to-Car Rear braking", "CCRb", _IL, "rel26",
         target_speed="Target_init_speed_kph"),
    _t26("CCFhos", "Car-to-Car Front head-on straight", "CCFhos", _IL, "headon26"),
    _t26("CCFtap", "Car-to-Car Front turn-across-path", "CCFtap", "Target_final_speed_kph",
         "avoidance"),
    _t26("CCCscp", "Car-to-Car Crossing straight crossing path", "CCCscp",
         "Target_final_speed_kph", "avoidance", col2="ImpactSide"),
    _t26("CMRs", "Car-to-Motorcyclist Rear stationary (AEB)", "CMRs", _IL, "rel26"),
    _t26("CMRs-FCW", "Car-to-Motorcyclist Rear stationary (FCW)", "CMRs_FCW", _IL, "fcw26",
         scenario="CMRs"),
    _t26("CMRb", "Car-to-Motorcyclist Rear braking", "CMRb", _IL, "rel26",
         target_speed="Target_init_speed_kph"),
    _t26("CMFtap", "Car-to-Motorcyclist Front turn-across-path", "CMFtap",
         "Target_final_speed_kph", "avoidance"),
    _t26("CMCscp", "Car-to-Motorcyclist Crossing straight crossing path", "CMCscp",
         "Target_final_speed_kph", "avoidance", col2="ImpactSide"),
    _t26("CPLA", "Pedestrian Longitudinal Adult (AEB)", "CPLA", _IL, "rel26",
         target_speed="Target_final_speed_kph", **_DN26),
    _t26("CPLA-FCW", "Pedestrian Longitudinal Adult (FCW)", "CPLA_FCW", _IL, "fcwttc26",
         scenario="CPLA", **_DN26),
    _t26("CPNA", "Pedestrian Nearside Adult", "CPNA", _IL, "rel26", **_DN26),
    _t26("CPFA", "Pedestrian Farside Adult", "CPFA", _IL, "rel26", **_DN26),
    _t26("CPNCO", "Pedestrian Nearside Child Obstructed", "CPNCO", _IL, "rel26", **_DN26),
    _t26("CBLA", "Bicyclist Longitudinal Adult (AEB)", "CBLA", _IL, "rel26",
         target_speed="Target_final_speed_kph"),
    _t26("CBLA-FCW", "Bicyclist Longitudinal Adult (FCW)", "CBLA_FCW", _IL, "fcwttc26",
         scenario="CBLA"),
    _t26("CBNA", "Bicyclist Nearside Adult", "CBNA", _IL, "rel26"),
    _t26("CBNAO", "Bicyclist Nearside Adult Obstructed", "CBNAO", _IL, "rel26"),
    _t26("CBFA", "Bicyclist Farside Adult", "CBFA", _IL, "rel26"),
)  # fmt: skip


def select_tests(protocol: str, only: tuple[str, ...] = ()) -> list[NcapTest]:
    """The tests of ``protocol`` ("c2c", "vru", "all": both, or "ca2026"), restricted to the
    keys in ``only`` when given; HiyariError for an unknown protocol or key."""
    if protocol not in (*PROTOCOL_NAMES, "all", CA2026):
        raise HiyariError(f"--protocol: unknown protocol {protocol!r} (c2c, vru, all or ca2026)")
    if protocol == CA2026:
        tests = list(TESTS_2026)
    else:
        tests = [t for t in TESTS if protocol in ("all", t.protocol)]
    unknown = sorted(set(only) - {t.key for t in tests})
    if unknown:
        known = ", ".join(t.key for t in tests)
        raise HiyariError(f"--tests: {', '.join(unknown)} not in protocol {protocol} ({known})")
    return [t for t in tests if not only or t.key in only]


def default_root() -> Path:
    """The Euro NCAP set: $HIYARI_NCAP_DIR, else data/openscenario/ncap in the checkout's shared
    folder (hiyari.checkout)."""
    env = os.environ.get(ENV_DIR)
    if env:
        return Path(env)
    return shared_dir() / "data" / "openscenario" / "ncap"


def variations_file(root: Path, test: NcapTest) -> Path:
    """The Variations file of ``test`` under ``root``; HiyariError naming it when missing."""
    path = root / "OpenSCENARIO" / "NCAP" / test.file
    if not path.is_file():
        raise HiyariError(f"{path}: no such file (test {test.key}; --files names the set)")
    return path
