"""A stochastic Histogram distribution: its bins (elements named Bin, of type HistogramBin)
are drawn by weight and a value uniformly inside the bin drawn, repeatably for a seed."""

from __future__ import annotations

from pathlib import Path

from openscenario_files import scenario_xml, teleport_speed, write

from hiyari.bridge.openscenario.xosc.distributions import read_distribution


def test_histogram_bins_by_weight(tmp_path: Path) -> None:
    write(tmp_path / "s.xosc", scenario_xml({"Ego": ""}, teleport_speed("Ego", -4, 20, 10),
                                            params='<ParameterDeclaration name="v" parameterType="double" value="1"/>'))  # fmt: skip
    dist = """<?xml version="1.0"?>
<OpenSCENARIO><FileHeader revMajor="1" revMinor="3" date="2026-01-01T00:00:00" description="d" author="t"/>
<ParameterValueDistribution><ScenarioFile filepath="s.xosc"/><Stochastic numberOfTestRuns="400" randomSeed="7">
<StochasticDistribution parameterName="v"><Histogram>
<Bin weight="3"><Range lowerLimit="0" upperLimit="1"/></Bin><Bin weight="1"><Range lowerLimit="10" upperLimit="11"/></Bin>
</Histogram></StochasticDistribution></Stochastic></ParameterValueDistribution></OpenSCENARIO>"""
    path = write(tmp_path / "d.xosc", dist)
    values = [float(r["v"]) for r in read_distribution(path).runs]
    low = [x for x in values if 0 <= x <= 1]
    high = [x for x in values if 10 <= x <= 11]
    assert len(low) + len(high) == 400 and 260 <= len(low) <= 340  # 3 : 1
    assert values == [float(r["v"]) for r in read_distribution(path).runs]
