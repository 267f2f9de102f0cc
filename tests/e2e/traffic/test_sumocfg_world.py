"""A user's own SUMO scenario (.sumocfg with its net, route and additional files and its time
window) read, run as traffic, and run with hiyari's ego inserted: its own demand intact
(the vehicles SUMO alone inserts, plus the ego), its buildings in the scene."""

from __future__ import annotations

import subprocess

import pytest
from lxml import etree
from runs import run_preset
from sumo_scenario_authoring import BEGIN, END, write_scenario

from hiyari.bridge.cli.main import main
from hiyari.bridge.loop.execute import RunOptions
from hiyari.bridge.openscenario.presets.scenarios import World
from hiyari.bridge.openscenario.presets.toml_file import parse_scenario
from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.road_mesh import network_scene_mesh
from hiyari.sumo_tools import sumo_binary, sumo_env
from hiyari.traffic.simulation import SimConfig
from hiyari.traffic.sumocfg import read_sumocfg
from hiyari.traffic.traffic_run import run_traffic


@pytest.fixture(scope="module")
def scenario(tmp_path_factory):
    return write_scenario(tmp_path_factory.mktemp("city"))


def test_read_sumocfg_resolves_files_and_window(scenario):
    sc = read_sumocfg(scenario)
    inputs = scenario.parent.parent / "in"
    assert sc.net.resolve() == (inputs / "town.net.xml").resolve()
    assert [p.name for p in sc.routes] == ["cars.rou.xml", "walks.rou.xml"]
    assert [p.name for p in sc.additional] == ["buildings.poly.xml"]
    assert (sc.begin, sc.end, sc.step_length) == (BEGIN, END, 0.5)
    cfg = SimConfig.from_sumocfg(scenario, step_length=0.1)
    assert (cfg.begin, cfg.end_time, cfg.step_length, cfg.config) == (BEGIN, END, 0.1, scenario)
    args = cfg.sumo_args(scenario)
    assert "--time-to-teleport" not in args  # the scenario keeps its own teleport setting


def test_clock_times_in_h_m_s(tmp_path, scenario):
    text = scenario.read_text().replace(f'"{BEGIN:g}"', '"0:01:40"')
    cfg = scenario.with_name("hms.sumocfg")
    cfg.write_text(text)
    assert read_sumocfg(cfg).begin == 100.0


def test_traffic_runs_over_the_scenario_window(scenario):
    summary = run_traffic(SimConfig.from_sumocfg(scenario), 60.0, progress=False)
    assert summary.times[0] == pytest.approx(BEGIN + 0.5)  # the window starts at its begin
    assert summary.vehicles_seen > 5 and summary.persons_seen > 3
    assert not summary.collisions


def _sumo_alone_departed(scenario, until: float, folder) -> set[str]:
    """Ids of the vehicles plain ``sumo -c`` inserts up to ``until`` s."""
    out = folder / "vehroutes.xml"
    subprocess.run(
        [str(sumo_binary("sumo")), "-c", str(scenario), "--end", repr(until),
         "--vehroute-output", str(out), "--vehroute-output.write-unfinished", "true",
         "--no-step-log", "true"],
        check=True, capture_output=True, env=sumo_env(),
    )  # fmt: skip
    root = etree.parse(str(out)).getroot()
    return {v.get("id") for v in root.iter("vehicle") if float(v.get("depart")) <= until}


def test_ego_inside_the_scenario_keeps_its_demand(scenario, tmp_path):
    world = World.of_sumocfg(scenario)
    network = world.network()
    assert len(network.buildings) == 2  # from the scenario's additional polygon file
    mesh = network_scene_mesh(network)
    assert (mesh.material == Material.BUILDING).sum() == 24  # two closed boxes
    logical = parse_scenario(
        {"scenario": {"type": "city", "duration": 25.0, "step_length": 0.1},
         "parameters": {"warmup_s": 10.0}},
        "city.toml",
    )  # fmt: skip
    (cs,) = logical.expand()
    seen: set[str] = set()
    last = [0.0]

    def collect(world_state, step, collisions) -> None:
        seen.update(world_state.ids[~world_state.is_pedestrian].tolist())
        last[0] = world_state.time

    run_preset(cs, RunOptions(), on_step=collect, world=world)
    assert "ego" in seen and last[0] > BEGIN + 10.0
    vehicles = seen - {"ego"}
    # every vehicle of the scenario present after the warm-up, and no other, as SUMO alone
    alone = _sumo_alone_departed(scenario, last[0], tmp_path)
    visible = {v for v in alone if v not in _arrived_before(scenario, BEGIN + 10.0, tmp_path)}
    assert vehicles == visible and len(vehicles) > 5


def _arrived_before(scenario, t: float, folder) -> set[str]:
    """Vehicles SUMO alone has already taken off the road at ``t`` s (before the ego came)."""
    out = folder / "trips.xml"
    subprocess.run(
        [str(sumo_binary("sumo")), "-c", str(scenario), "--end", repr(t),
         "--tripinfo-output", str(out), "--no-step-log", "true"],
        check=True, capture_output=True, env=sumo_env(),
    )  # fmt: skip
    return {v.get("id") for v in etree.parse(str(out)).getroot().iter("tripinfo")}


def test_world_only_for_city_runs(scenario, tmp_path):
    toml = tmp_path / "cut.toml"
    toml.write_text('[scenario]\ntype = "decel"\n[parameters]\nve0_kmh = 60\ngx_max_g = 0.5\n')
    with pytest.raises(HiyariError, match="only city scenarios"):
        from hiyari.bridge.openscenario.presets.scenarios import build_scenario
        from hiyari.bridge.openscenario.presets.toml_file import load_scenario

        build_scenario(load_scenario(toml).expand()[0], tmp_path / "w", world=World(scenario))


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda t: t.replace("walks.rou.xml", "gone.rou.xml"), "names ../in/route/gone.rou.xml"),
        (lambda t: t.replace("../in/town.net.xml", "../in/none.net.xml"), "which does not exist"),
        (lambda t: t.replace('<end value="700"/>', '<end value="50"/>'), "is not after begin"),
        (
            lambda t: t.replace("<configuration>", "<net>").replace("</configuration>", "</net>"),
            "not a SUMO configuration",
        ),  # fmt: skip
        (lambda t: t[: len(t) // 2], "not well-formed XML"),
    ],
)
@pytest.mark.parametrize("command", [["run", "--sumocfg"], ["sim", "--config"]])
def test_bad_sumocfg_one_line_exit_1(scenario, tmp_path, capsys, edit, words, command):
    bad = scenario.with_name("bad.sumocfg")
    bad.write_text(edit(scenario.read_text()))
    out = tmp_path / "out"
    assert main([*command, str(bad), "-o" if command[0] == "run" else "-q", *(
        [str(out)] if command[0] == "run" else [])]) == 1  # fmt: skip
    err = capsys.readouterr().err
    assert err.startswith(f"hiyari: error: {bad}: ") and words in err and err.count("\n") == 1
    assert not out.exists()


def test_run_ends_inside_the_window(scenario, tmp_path, capsys):
    toml = tmp_path / "long.toml"
    toml.write_text('[scenario]\ntype = "city"\nduration = 900\n')
    assert main(["run", str(toml), "--sumocfg", str(scenario), "-o", str(tmp_path / "o")]) == 1
    assert "ends after the scenario's end 700 s" in capsys.readouterr().err
