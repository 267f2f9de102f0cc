"""An OpenSCENARIO storyboard run inside the user's SUMO scenario (``hiyari run x.xosc
--sumocfg s.sumocfg``): the scenario's own demand runs around it as plain SUMO runs it (the
same vehicles, plus the storyboard's ego), and a scenario whose net is not the conversion of
the road the .xosc names is refused in one line before anything is written."""

from __future__ import annotations

import subprocess

import pytest
from lxml import etree
from openscenario_files import STRAIGHT, net_for, scenario_xml, teleport_speed, time_condition
from sumo_scenario_authoring import ROAD_BEGIN, write_road_scenario

from hiyari.bridge.cli.main import main
from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.spec import EgoSetup
from hiyari.bridge.loop.xosc_runs import load_plan
from hiyari.sumo_tools import sumo_binary, sumo_env
from hiyari.traffic.sumocfg import read_sumocfg

WARMUP, DURATION, STEP = 10.0, 12.0, 0.1
ROADS = STRAIGHT.parent


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("xosc_world")
    cfg = write_road_scenario(folder / "scenario", net_for(STRAIGHT, folder))
    stop = f"<ConditionGroup>{time_condition(8.0)}</ConditionGroup>"
    xosc = folder / "drive.xosc"
    xosc.write_text(scenario_xml({"ego": ""}, teleport_speed("ego", -2, 50.0, 25.0), stop=stop))
    return xosc, cfg


def _sumo_alone_departed(cfg, until: float, folder) -> set[str]:
    """Ids of the vehicles plain ``sumo -c`` inserts up to ``until`` s at the run's step."""
    out = folder / "vehroutes.xml"
    subprocess.run(
        [str(sumo_binary("sumo")), "-c", str(cfg), "--end", repr(until),
         "--step-length", repr(STEP), "--vehroute-output", str(out),
         "--vehroute-output.write-unfinished", "true", "--no-step-log", "true"],
        check=True, capture_output=True, env=sumo_env(),
    )  # fmt: skip
    return {v.get("id") for v in etree.parse(str(out)).getroot().iter("vehicle")}


def test_storyboard_runs_with_the_scenario_demand_intact(files, tmp_path):
    xosc, cfg = files
    setup = EgoSetup(step_length=STEP, max_duration=DURATION)
    (run,) = load_plan(xosc, setup, sumo=read_sumocfg(cfg), warmup=WARMUP).expand()
    seen: set[str] = set()
    times: list[float] = []

    def collect(world, step, collisions) -> None:
        seen.update(world.ids.tolist())
        times.append(world.time)

    with run.spec() as spec:
        assert spec.road.sumo is not None and spec.warmup == WARMUP
        result = execute(spec, RunOptions(), collect)
    assert not result.collision
    # the storyboard starts after the warm-up, inside the scenario's window
    assert times[0] == pytest.approx(ROAD_BEGIN + WARMUP + STEP)
    assert times[-1] == pytest.approx(ROAD_BEGIN + WARMUP + 8.0, abs=3 * STEP)
    alone = _sumo_alone_departed(cfg, times[-1], tmp_path)
    assert seen - {"ego"} == alone and "ego" in seen
    assert len([v for v in alone if v.startswith("vans")]) >= 2  # the additional file's type


def test_cli_run_writes_the_world_into_the_result(files, tmp_path, capsys):
    xosc, cfg = files
    out = tmp_path / "out"
    argv = ["run", str(xosc), "--sumocfg", str(cfg), "--warmup", "5", "--max-duration", "10",
            "--step-length", "0.1", "--no-record", "-q", "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    doc = (out / "result.json").read_text()
    assert str(cfg) in doc and '"warmup_s": 5.0' in doc


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda t, _: t.replace("road.rou.xml", "gone.rou.xml"), "names gone.rou.xml"),
        (
            lambda t, net: t.replace(str(net), str(ROADS / "alks_road_left_radius_250m.xodr")),
            "not a SUMO network",
        ),
        (lambda t, _: t.replace('"200"', '"70"'), "ends after the scenario's end 70 s"),
    ],
)
def test_bad_world_one_line_exit_1(files, tmp_path, capsys, edit, words):
    xosc, cfg = files
    net = read_sumocfg(cfg).net
    bad = cfg.with_name("bad.sumocfg")
    bad.write_text(edit(cfg.read_text(), net))
    out = tmp_path / "out"
    assert main(["run", str(xosc), "--sumocfg", str(bad), "--warmup", "10", "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"hiyari: error: {bad}: ") and words in err and err.count("\n") == 1
    assert not out.exists()


def test_net_of_another_road_is_refused(files, tmp_path, capsys):
    xosc, cfg = files
    other = net_for(ROADS / "alks_road_left_radius_250m.xodr", tmp_path)
    bad = cfg.with_name("other_road.sumocfg")
    bad.write_text(cfg.read_text().replace(str(read_sumocfg(cfg).net), str(other)))
    out = tmp_path / "out"
    assert main(["run", str(xosc), "--sumocfg", str(bad), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"hiyari: error: {bad}: its net {other.name} is not the conversion "
                          "of alks_road_straight.xodr") and err.count("\n") == 1  # fmt: skip
    assert "hiyari net import alks_road_straight.xodr" in err
    assert not out.exists()


def test_scenario_vehicle_named_as_an_entity_refused(files, tmp_path, capsys):
    xosc, cfg = files
    routes = cfg.with_name("road.rou.xml").read_text()
    clash = cfg.with_name("clash.rou.xml")
    clash.write_text(routes.replace("</routes>", '<vehicle id="ego" depart="55"><route '
                                    'edges="-0"/></vehicle></routes>'))  # fmt: skip
    bad = cfg.with_name("clash.sumocfg")
    bad.write_text(cfg.read_text().replace("road.rou.xml", clash.name))
    out = tmp_path / "out"
    argv = ["run", str(xosc), "--sumocfg", str(bad), "--warmup", "10", "--max-duration", "5",
            "-q", "-o", str(out)]  # fmt: skip
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "cannot insert 'ego': the simulation already has a vehicle" in err
    assert err.count("\n") == 1 and not out.exists()


def test_map_and_stray_warmup_refused(files, tmp_path, capsys):
    xosc, cfg = files
    out = str(tmp_path / "out")
    assert main(["run", str(xosc), "--map", str(read_sumocfg(cfg).net), "-o", out]) == 1
    assert "runs on the road its LogicFile names" in capsys.readouterr().err
    assert main(["run", str(xosc), "--warmup", "5", "-o", out]) == 1
    assert "--warmup: the warm-up is of a SUMO scenario's demand" in capsys.readouterr().err


def test_sweep_takes_the_same_world(files, tmp_path, capsys):
    """``hiyari sweep x.xosc --sumocfg``: the run goes inside the scenario (its net checked
    before any run: another road's net is refused in one line), and runs to its end."""
    from hiyari.bridge.studies.sweep import read_table

    xosc, cfg = files
    other = net_for(ROADS / "alks_road_left_radius_250m.xodr", tmp_path)
    bad = cfg.with_name("sweep_other_road.sumocfg")
    bad.write_text(cfg.read_text().replace(str(read_sumocfg(cfg).net), str(other)))
    common = ["--warmup", "5", "--max-duration", "10", "--step-length", "0.1", "-j", "1", "-q"]
    assert (
        main(["sweep", str(xosc), "--sumocfg", str(bad), *common, "-o", str(tmp_path / "b")]) == 1
    )
    assert "is not the conversion of alks_road_straight.xodr" in capsys.readouterr().err
    assert not (tmp_path / "b").exists()
    out = tmp_path / "sweep"
    assert main(["sweep", str(xosc), "--sumocfg", str(cfg), *common, "-o", str(out)]) == 0
    (row,) = read_table(out / "results.csv").values()
    assert row["status"] == "ok" and row["collision"] == "False"
