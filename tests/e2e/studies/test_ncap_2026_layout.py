"""``hiyari ncap --protocol ca2026`` on the 2026 folder layout (CA-FC_2026/Variations/
StandardRange, day and night in the file's own grid), built here from the shared 2023 CPNA
scenario: the plan reads each run's lighting from its LightingConditions parameter, and the
study runs on real SUMO and scores the points with the 2026 rules (score.json)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from paths import SHARED

from hiyari.bridge.cli.main import main
from hiyari.bridge.studies.ncap.study import NIGHT_PRESET, NcapOptions, plan

pytestmark = pytest.mark.slow

NCAP = SHARED / "data" / "openscenario" / "ncap"
VARIATION = """<?xml version='1.0' encoding='utf-8'?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="3" date="2026-02-24T14:44:00" author="test" description="CPNA"/>
  <ParameterValueDistribution>
    <ScenarioFile filepath="../../CPNA.xosc" />
    <Deterministic>
      <DeterministicSingleParameterDistribution parameterName="Ego_speed_kph">
        <DistributionSet><Element value="20" /><Element value="50" /></DistributionSet>
      </DeterministicSingleParameterDistribution>
      <DeterministicSingleParameterDistribution parameterName="LightingConditions">
        <DistributionSet><Element value="Sunny" /><Element value="Night" /></DistributionSet>
      </DeterministicSingleParameterDistribution>
    </Deterministic>
  </ParameterValueDistribution>
</OpenSCENARIO>
"""


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A set root with CA-FC_2026/CPNA.xosc (the 2023 CPNA with a LightingConditions
    parameter) and its StandardRange Variations file; catalogs and roads are the shared set's."""
    root = tmp_path_factory.mktemp("ncap2026")
    ncap = root / "OpenSCENARIO" / "NCAP"
    (ncap / "CA-FC_2026" / "Variations" / "StandardRange").mkdir(parents=True)
    (ncap / "Catalogs").symlink_to(NCAP / "OpenSCENARIO" / "NCAP" / "Catalogs")
    (root / "OpenDRIVE").symlink_to(NCAP / "OpenDRIVE")
    base = NCAP / "OpenSCENARIO" / "NCAP" / "AEB_VRU_2023" / "NCAP_AEB_VRU_CPNA_2023.xosc"
    text = base.read_text().replace(
        "<ParameterDeclarations>",
        '<ParameterDeclarations>\n    <ParameterDeclaration name="LightingConditions" '
        'parameterType="string" value="Sunny" />',
        1,
    )
    (ncap / "CA-FC_2026" / "CPNA.xosc").write_text(text)
    (ncap / "CA-FC_2026" / "Variations" / "StandardRange" / "CPNA.xosc").write_text(VARIATION)
    return root


def test_plan_reads_the_lighting_from_each_run(root: Path, tmp_path: Path) -> None:
    points = plan(NcapOptions(tmp_path / "out", protocol="ca2026", files=root, only=("CPNA",)))
    got = sorted((p.lighting, p.run.params["Ego_speed_kph"]) for p in points)
    assert got == [("day", "20"), ("day", "50"), ("night", "20"), ("night", "50")]
    for p in points:
        night = p.run.params["LightingConditions"] == "Night"
        assert (p.lighting == "night") is night
        assert (p.run.setup.environment == NIGHT_PRESET) is night
    assert not (tmp_path / "out").exists()  # planning writes nothing


def test_study_scores_the_2026_grid(root: Path, tmp_path: Path) -> None:
    out = tmp_path / "study"
    args = ["ncap", "--protocol", "ca2026", "--files", str(root), "--tests", "CPNA",
            "--speeds", "20", "-j", "1", "-q", "--no-replays", "-o", str(out)]  # fmt: skip
    assert main(args) in (0, 3)
    doc = json.loads((out / "score.json").read_text())
    cpna = doc["ca2026"]["scenarios"]["CPNA"]
    assert cpna["max_points"] == 1.0 and cpna["tested"] + cpna["not_tested"] == 2
    assert 0.0 <= cpna["points"] <= 1.0
    assert "2026 Crash Avoidance" in (out / "report.html").read_text()
