"""Bad input to `hiyari sim`: one clear line naming the problem, exit 1, no traceback."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

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


# ---------------------------------------------------------------- in-process CLI (issue 17)
def _main(capsys, *args: str) -> tuple[int, str, str]:
    from hiyari.bridge.cli.main import main

    status = main(list(args))
    out, err = capsys.readouterr()
    return status, out, err


def _one_line(status: int, err: str, *needles: str) -> str:
    assert status == 1, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("hiyari: error: "), err
    for n in needles:
        assert n in lines[0], lines[0]
    return lines[0]


def _net_with(net: Path, old: str, new: str, out: Path) -> Path:
    text = net.read_text()
    assert old in text
    out.write_text(text.replace(old, new, 1))
    return out


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "-1", "0", "1e300", "ten"])
def test_sim_duration_not_a_usable_number(intersection_net, capsys, value):
    status, _, err = _main(capsys, "sim", "-n", str(intersection_net), "-q", f"-d={value}")
    _one_line(status, err, "--duration", repr(value))


def test_sim_json_in_missing_folder_fails_before_running(intersection_net, tmp_path, capsys):
    target = tmp_path / "no" / "such" / "dir" / "s.json"
    status, out, err = _main(
        capsys, "sim", "-n", str(intersection_net), "-q", "-d", "30", "--json", str(target)
    )
    _one_line(status, err, "s.json", "does not exist")
    assert "simulated" not in out  # refused before SUMO ran
    assert not (tmp_path / "no").exists()


def test_sim_json_written_whole(intersection_net, tmp_path, capsys):
    target = tmp_path / "s.json"
    status, _, err = _main(
        capsys, "sim", "-n", str(intersection_net), "-q", "-d", "5", "--json", str(target)
    )
    assert status == 0, err
    import json

    assert json.loads(target.read_text())["steps"] == 50
    assert [p.name for p in tmp_path.iterdir()] == ["s.json"]  # no .part left


def test_sumo_load_error_is_one_line_naming_the_net(intersection_net, tmp_path, capsys):
    bad = _net_with(intersection_net, 'shape="', 'shape="1,2,x ', tmp_path / "badshape.net.xml")
    status, _, err = _main(capsys, "sim", "-n", str(bad), "-q", "-d", "5")
    line = _one_line(status, err, str(bad), "Invalid Number Format", "more error")
    assert "Error:" not in err and "/tmp" not in line.replace(str(tmp_path), "")


def test_sumo_route_error_names_the_route_file(intersection_net, tmp_path, capsys):
    routes = tmp_path / "ghost.rou.xml"
    routes.write_text(
        '<routes><vehicle id="v0" depart="0"><route edges="nope1 nope2"/></vehicle></routes>'
    )
    status, _, err = _main(
        capsys, "sim", "-n", str(intersection_net), "-r", str(routes), "-q", "-d", "5"
    )
    line = _one_line(status, err, "nope1")
    assert line.startswith(f"hiyari: error: {routes}: ")


def test_generated_demand_is_never_named(intersection_net, tmp_path, capsys):
    routes = tmp_path / "ghost.rou.xml"
    routes.write_text(
        '<routes><vehicle id="v0" depart="0"><route edges="nope1"/></vehicle></routes>'
    )
    status, _, err = _main(
        capsys,
        "sim",
        "-n",
        str(intersection_net),
        "-r",
        str(routes),
        "--vph",
        "300",
        "-q",
        "-d",
        "5",
    )
    line = _one_line(status, err, str(routes))
    assert "hiyari-sim-" not in line and "demand.rou.xml" not in line


@pytest.mark.parametrize(
    "old, new, complaint",
    [
        ('shape="', 'shape="1,2,x ', "Invalid Number Format"),
        ('from="C"', 'from="NOPE"', "NOPE"),
    ],
)
def test_net_mesh_refuses_a_net_sumo_rejects(
    intersection_net, tmp_path, capsys, old, new, complaint
):
    if old not in intersection_net.read_text():
        old = 'from="' + intersection_net.read_text().split('from="', 1)[1].split('"', 1)[0] + '"'
    bad = _net_with(intersection_net, old, new, tmp_path / "bad.net.xml")
    glb = tmp_path / "scene.glb"
    status, _, err = _main(capsys, "net", "mesh", str(bad), "-o", str(glb))
    _one_line(status, err, str(bad), "SUMO cannot load", complaint)
    assert not glb.exists() and [p.name for p in tmp_path.iterdir()] == ["bad.net.xml"]


def test_usage_errors_are_one_line(capsys):
    status, _, err = _main(capsys, "sim", "--duration", "5")
    _one_line(status, err, "--config", "--net")


def test_usage_errors_name_the_program_once():
    top = _hiyari("demo", "--bogus")
    _assert_one_line_error(top, "unrecognized arguments: --bogus")
    assert top.stderr.count("hiyari") == 1, top.stderr
    sub = _hiyari("run")
    _assert_one_line_error(sub, "hiyari run: ", "required: scenario")
