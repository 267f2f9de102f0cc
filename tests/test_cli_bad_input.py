"""Bad input to `hiyari sim`: one clear line naming the problem, exit 1, no traceback."""

from __future__ import annotations

import subprocess
import sys

import pytest


def _hiyari(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "hiyari", *args], capture_output=True, text=True, timeout=120
    )


def _assert_one_line_error(proc, *needles: str) -> None:
    assert proc.returncode == 1, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("hiyari: error:")
    assert "Traceback" not in proc.stderr
    for n in needles:
        assert n in lines[0], lines[0]


def test_missing_net(tmp_path):
    _assert_one_line_error(
        _hiyari("sim", "-n", str(tmp_path / "nope.net.xml")), "nope.net.xml", "not found"
    )


def test_malformed_net(tmp_path):
    bad = tmp_path / "bad.net.xml"
    bad.write_text("<net><edge id='a'>")
    _assert_one_line_error(_hiyari("sim", "-n", str(bad)), "bad.net.xml", "not well-formed")


def test_not_a_net(tmp_path):
    bad = tmp_path / "routes.xml"
    bad.write_text("<routes/>")
    _assert_one_line_error(_hiyari("sim", "-n", str(bad)), "routes.xml", "not a SUMO network")


def test_missing_and_malformed_routes(intersection_net, tmp_path):
    _assert_one_line_error(
        _hiyari("sim", "-n", str(intersection_net), "-r", str(tmp_path / "r.rou.xml")),
        "r.rou.xml",
        "not found",
    )
    bad = tmp_path / "bad.rou.xml"
    bad.write_text("<routes><vehicle id='x'")
    _assert_one_line_error(
        _hiyari("sim", "-n", str(intersection_net), "-r", str(bad)), "bad.rou.xml", "well-formed"
    )


def test_negative_duration(intersection_net):
    _assert_one_line_error(_hiyari("sim", "-n", str(intersection_net), "-d", "-5"), "duration")


def test_unknown_vehicle_type_in_routes(intersection_net, tmp_path):
    routes = tmp_path / "unknown_type.rou.xml"
    routes.write_text(
        '<routes><vehicle id="v0" type="hovercraft" depart="0">'
        '<route edges="w_in e_out"/></vehicle></routes>'
    )
    _assert_one_line_error(
        _hiyari("sim", "-n", str(intersection_net), "-r", str(routes), "-d", "5"), "hovercraft"
    )


def test_unknown_vehicle_type_in_mix(intersection_net):
    _assert_one_line_error(
        _hiyari("sim", "-n", str(intersection_net), "--vph", "100", "--mix", "car=1,tank=1"),
        "tank",
        "unknown vehicle type",
    )


@pytest.mark.parametrize("step", ["0", "-0.1"])
def test_impossible_step_length(intersection_net, step):
    _assert_one_line_error(
        _hiyari("sim", "-n", str(intersection_net), "--step", step), "step length"
    )


def test_sim_runs_generated_demand(intersection_net, tmp_path):
    out = tmp_path / "summary.json"
    proc = _hiyari(
        "sim",
        "-n",
        str(intersection_net),
        "--vph",
        "600",
        "--pph",
        "600",
        "-d",
        "120",
        "-q",
        "--json",
        str(out),
    )
    assert proc.returncode == 0, proc.stderr
    assert "steps/s" in proc.stdout
    import json

    d = json.loads(out.read_text())
    assert d["steps"] == 1200 and d["vehicles_seen"] > 5 and d["persons_seen"] > 5


def test_doctor_reports_parts():
    proc = _hiyari("doctor")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    for part in ("SUMO", "libsumo", "Embree", "ray cast ok"):
        assert part in proc.stdout
