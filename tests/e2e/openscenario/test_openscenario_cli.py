"""``hiyari run`` / ``hiyari sweep`` on OpenSCENARIO files: real runs, distributions expanded
into sweeps, and bad input as one line with nothing written."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from openscenario_files import (
    ALKS,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.bridge.cli.main import main

CUT_IN = next(ALKS.glob("alks_scenario_4_4_1_*.xosc"))


def _distribution(path: Path, scenario: Path, values: list[float]) -> Path:
    elements = "".join(f'<Element value="{v}"/>' for v in values)
    return write(
        path,
        f"""<?xml version="1.0" encoding="utf-8"?>
<OpenSCENARIO>
<FileHeader revMajor="1" revMinor="3" date="2026-01-01T00:00:00" description="d" author="hiyari"/>
<ParameterValueDistribution><ScenarioFile filepath="{scenario}"/>
<Deterministic><DeterministicSingleParameterDistribution parameterName="CutInVehicle_HeadwayDistanceTrigger_dx0_m">
<DistributionSet>{elements}</DistributionSet></DeterministicSingleParameterDistribution></Deterministic>
</ParameterValueDistribution></OpenSCENARIO>""",
    )


def test_run_xosc_writes_result_recording_and_table(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    out = tmp_path / "out"
    assert main(["run", str(CUT_IN), "-o", str(out), "-q"]) == 0
    line = capsys.readouterr().out.splitlines()[0]
    assert "no collision" in line and "min TTC" in line and "min gap" in line
    doc = json.loads((out / "result.json").read_text())
    assert doc["result"]["stop_trigger"] is True
    assert doc["scenario"]["perception"] == "perfect" and doc["scenario"]["ego"] == "Ego"
    assert (out / "run.mcap").is_file() and (out / "timeseries.png").is_file()
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert len(rows) == 1 and rows[0]["collision"] == "False"


def test_sweep_expands_a_distribution_into_its_runs(tmp_path: Path) -> None:
    """Three dx0 values -> three rows with those values, each run seeded 1 + index; a larger
    headway trigger makes the cut-in happen farther ahead: min TTC grows with dx0."""
    dist = _distribution(tmp_path / "d.xosc", CUT_IN, [20.0, 30.0, 40.0])
    out = tmp_path / "sweep"
    assert main(["sweep", str(dist), "-o", str(out), "-j", "1", "-q"]) == 0
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [r["CutInVehicle_HeadwayDistanceTrigger_dx0_m"] for r in rows] == [
        "20.0",
        "30.0",
        "40.0",
    ]
    assert [r["seed"] for r in rows] == ["1", "2", "3"]
    assert all(r["status"] == "ok" for r in rows)
    ttc = [float(r["min_ttc_s"] or "inf") for r in rows]
    assert ttc[0] < ttc[1] <= ttc[2]
    assert (out / "summary.png").is_file()


def _bad(tmp_path: Path, capsys, argv: list[str], *expected: str) -> None:  # noqa: ANN001
    out = tmp_path / "out"
    assert main([*argv, "-o", str(out), "-q"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hiyari: error: "), err
    for text in expected:
        assert text in err[0], err[0]
    assert not out.exists()


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_bad_xosc_is_one_line_naming_file_and_line(tmp_path: Path, capsys, command: str) -> None:  # noqa: ANN001
    ok = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -4, 5.0, 10.0) + teleport_speed("Car", -5, 5.0, 10.0),
    )
    invalid = write(
        tmp_path / "invalid.xosc", ok.replace('dynamicsShape="step"', 'dynamicsShape="x"', 1)
    )
    line = ok[: ok.index('dynamicsShape="step"')].count("\n") + 1
    _bad(tmp_path, capsys, [command, str(invalid)], f"{invalid}:{line}: not valid OpenSCENARIO")

    unknown = write(tmp_path / "unknown.xosc", ok.replace('s="5.0"', 's="$Nowhere"', 1))
    _bad(tmp_path, capsys, [command, str(unknown)], str(unknown), "unknown parameter $Nowhere")

    gone = write(tmp_path / "gone.xosc", scenario_xml({"Ego": ""}, "", road=tmp_path / "no.xodr"))
    _bad(tmp_path, capsys, [command, str(gone)], str(gone), "no.xodr not found")

    custom = '<UserDefinedAction><CustomCommandAction type="kick">now</CustomCommandAction></UserDefinedAction>'
    xml = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -4, 5.0, 10.0) + teleport_speed("Car", -5, 5.0, 10.0),
        story("Car", "MARK", time_condition(1.0)),
    ).replace("<PrivateAction>MARK</PrivateAction>", custom)
    unsupported = write(tmp_path / "custom.xosc", xml)
    line = xml[: xml.index("<UserDefinedAction")].count("\n") + 1
    _bad(
        tmp_path,
        capsys,
        [command, str(unsupported)],
        f"{unsupported}:{line}: <UserDefinedAction> is not supported",
    )
