"""``hiyari run`` options on real scenarios: ``--param`` sets an OpenSCENARIO parameter
(checked against its declaration), ``--dry-run`` makes every check a run makes before its
first step and writes nothing, ``--environment`` applies to TOML presets too, and the
progress bar of an .xosc run counts to the run's own end."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from openscenario_files import ALKS

from hiyari.bridge.cli import status
from hiyari.bridge.cli.main import main

CUT_IN = next(ALKS.glob("alks_scenario_4_4_1_*.xosc"))
# the speed action that accelerates the cut-in car to 40 km/h at 0 m/s² (line 189)
RATE_ZERO = f"{CUT_IN}:189: SpeedAction: transition rate value must be positive, got 0"


def _one_line(capsys, *needles: str) -> str:  # noqa: ANN001
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hiyari: error: "), err
    for n in needles:
        assert n in err[0], err[0]
    return err[0]


@pytest.mark.parametrize("dry", [True, False])
def test_speed_the_storyboard_cannot_reach_is_refused_before_anything_runs(
    tmp_path: Path, capsys, dry: bool
) -> None:  # noqa: ANN001
    """Ego_InitSpeed_Ve0_kph = 50 meets its constraint (0 < v <= 60), but the cut-in car then
    starts at 50 - 20 = 30 km/h and its acceleration to 40 km/h has a rate of 0: the dry run
    refuses it as the run does, and the run refuses it before its first step."""
    out = tmp_path / "out"
    argv = ["run", str(CUT_IN), "--param", "Ego_InitSpeed_Ve0_kph=50", "-q", "-o", str(out)]
    assert main(argv + ["--dry-run"] * dry) == status.ERROR
    assert _one_line(capsys) == f"hiyari: error: {RATE_ZERO}"
    assert not out.exists()  # no run.mcap.part, no roads/


@pytest.mark.parametrize(
    "param, needles",
    [
        ("Ego_InitSpeed_Ve0_kph=70", [f"{CUT_IN}:9:", "= 70.0 violates its constraint groups"]),
        ("Ego_InitSpeed_Ve0_kph=fast", [f"{CUT_IN}:9:", "'fast' is not a double"]),
        ("CutInVehicle_InitPosition_RelativeLaneId=1.5", [f"{CUT_IN}:19:", "is an int"]),
        ("Nope=1", [f"{CUT_IN}:3:", "no parameter Nope is declared here"]),
        ("Ego_InitSpeed_Ve0_kph", ["--param: expected NAME=VALUE"]),
    ],
)
def test_bad_param_is_one_line(tmp_path: Path, capsys, param: str, needles: list[str]) -> None:  # noqa: ANN001
    out = tmp_path / "out"
    assert main(["run", str(CUT_IN), "--param", param, "--dry-run", "-o", str(out)]) == 1
    _one_line(capsys, *needles)
    assert not out.exists()


def test_dry_run_of_a_good_file_writes_nothing(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    out = tmp_path / "out"
    lane = "CutInVehicle_InitPosition_RelativeLaneId=1"  # the other constraint group
    assert main(["run", str(CUT_IN), "--param", lane, "--dry-run", "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].endswith(f"#0 {lane}: ready")
    assert "checked up to their first step" in lines[-1]
    assert not out.exists()


def test_param_reaches_the_run_and_the_bar_ends_with_it(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    """dx0 = 40 m: the cut-in starts 10 m earlier than at the file's 30 m. The progress bar
    ends at the steps the run took (the stop trigger), not at the 600 s cap (12000 steps)."""
    out = tmp_path / "out"
    dx0 = "CutInVehicle_HeadwayDistanceTrigger_dx0_m=40"
    assert main(["run", str(CUT_IN), "--param", dx0, "--no-record", "-o", str(out)]) == 0
    doc = json.loads((out / "result.json").read_text())
    assert doc["scenario"]["params"]["CutInVehicle_HeadwayDistanceTrigger_dx0_m"] == "40.0"
    assert doc["result"]["stop_trigger"] is True
    bars = re.findall(r"(\d+)/(\d+) \[", capsys.readouterr().err)
    assert bars, "no progress bar"
    done, total = map(int, bars[-1])
    assert done == total == round(doc["result"]["sim_seconds"] / 0.05)
    assert total < 600 / 0.05


TOML = """
[scenario]
type = "cut-in"
duration = 1
step_length = 0.05
[ego]
perception = "none"
[environment]
preset = "rain"
[parameters]
ve0_kmh = 60
vo0_kmh = 40
dx0_m = 30
vy_ms = 1.0
"""


def test_environment_applies_to_toml_presets(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    scen = tmp_path / "cut_in.toml"
    scen.write_text(TOML)
    for given, recorded in (([], "rain"), (["--environment", "fog"], "fog")):
        out = tmp_path / recorded
        assert main(["run", str(scen), *given, "--no-record", "-q", "-o", str(out)]) == 0
        doc = json.loads((out / "result.json").read_text())
        assert doc["scenario"]["environment"] == recorded
    assert main(["run", str(scen), "--environment", "smog", "-o", str(tmp_path / "x")]) == 1
    _one_line(capsys, "--environment: unknown disturbance preset 'smog'")
    assert not (tmp_path / "x").exists()
