"""The Euro NCAP 2023 files of ../shared (Vector's OSC-NCAP-scenarios): every concrete file
reads, its Variations files expand into the protocol's grids, and representative files run on
SUMO with the ego at its test speed (no AEB), their targets meeting the ego where the protocol
puts the impact (benchmarks/ncap_meeting.py measures all 13)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from paths import REPO_ROOT

from hiyari.bridge.openscenario.xosc.distributions import read_distribution
from hiyari.bridge.openscenario.xosc.reader import read_scenario

sys.path.insert(0, str(REPO_ROOT / "benchmarks"))
import ncap_meeting  # noqa: E402

NCAP = ncap_meeting.NCAP / "OpenSCENARIO" / "NCAP"
#: Runs in each protocol grid: test speeds x overlaps / impact positions (C2C 4.3.1, VRU 4.5.1).
GRIDS = {
    "NCAP_AEB_C2C_CCRs_Variation_2023": 45,  # 10..50 km/h step 5 x 5 overlaps
    "NCAP_AEB_C2C_CCRm_Variation_2023": 55,  # 30..80 km/h step 5 x 5 overlaps
    "NCAP_AEB_C2C_CCRb_Variation_2023": 4,  # 12 / 40 m x 2 / 6 m/s^2
    "NCAP_AEB_C2C_CCFtap_Variation_2023": 9,  # 10 / 15 / 20 km/h x 30 / 45 / 60 km/h
    "NCAP_AEB_VRU_CPNA-25_Variation_2023": 11,  # 10..60 km/h step 5
    "NCAP_AEB_VRU_CPRA_Cs_Variation_2023": 6,
}


def test_every_concrete_file_reads() -> None:
    files = ncap_meeting.FILES
    assert len(files) == 13
    for f in files:
        sc = read_scenario(f)
        assert sc.ego == "Ego" and sc.variables["collisionDetected"] == ("boolean", "false")


@pytest.mark.parametrize("name", sorted(GRIDS))
def test_variations_expand_into_the_protocol_grid(name: str) -> None:
    path = next(NCAP.glob(f"*/Variations/{name}.xosc"))
    assert len(read_distribution(path).runs) == GRIDS[name]


@pytest.mark.parametrize("stem", ["VRU_CPNA", "C2C_CCFtap", "VRU_CPRA_Cs"])
def test_targets_meet_the_ego_at_the_impact_point(stem: str, tmp_path: Path) -> None:
    path = next(f for f in ncap_meeting.FILES if f.stem == f"NCAP_AEB_{stem}_2023")
    row = ncap_meeting.measure(path, 0.05, {}, tmp_path)
    assert row["end"] == "contact"
    if "sync error" in row:  # the target at its synchronisation point when the ego is at its
        assert abs(row["sync error"]) < 0.01
    expected_y = {  # the target's box centre across the ego when they touch (m, left +)
        "VRU_CPNA": -0.394,  # 25 % of the 1.815 m front from the nearside, + 0.06 m contact offset
        "C2C_CCFtap": None,
        "VRU_CPRA_Cs": 0.0,  # 50 %: behind the middle of the backing ego
    }[stem]
    if expected_y is not None:
        assert row["y"] == pytest.approx(expected_y, abs=0.02)
    if stem == "VRU_CPRA_Cs":
        assert row["x"] < -0.8  # behind the rear bumper (0.83 m behind the rear axle)
