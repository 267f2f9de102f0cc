"""The SCT study on a real map and inside a user's SUMO scenario: ``--crossings auto`` finds
the map's own crossings (SUMO crossing edges), the study's pedestrians walk across the chosen
ones, the scenario's own demand runs with them, and a bad crossing id or scenario is one
line with exit status 1 and nothing written. The map is the OSM test town (a mapped zebra
crossing mid-block, a signalised junction, guessed crossings elsewhere)."""

from __future__ import annotations

import numpy as np
import pytest
from osm_authoring import town
from sumo_scenario_authoring import BEGIN, write_scenario

from hiyari.bridge.cli.main import main
from hiyari.bridge.studies.sct.study import (
    WORLD_VARIANT,
    StudyConfig,
    build_inputs,
    run_arm,
    study_world,
)
from hiyari.traffic.demand import crossing_ids
from hiyari.traffic.simulation import Simulation
from hiyari.traffic.sumocfg import read_sumocfg

RUN_S = 120.0
IDS = town().ids  # the OSM ids are the junction ids of the import
ZEBRA, SIGNAL = str(IDS["crossing"]), str(IDS["E"])


@pytest.fixture(scope="module")
def scenario(tmp_path_factory):
    return write_scenario(tmp_path_factory.mktemp("sct_city"))


@pytest.fixture(scope="module")
def net(scenario):
    return read_sumocfg(scenario).net


def _config(**kw) -> StudyConfig:
    kw = {"days": RUN_S / 86400, "runs": 1, "variants": (WORLD_VARIANT,),
          "persons_per_hour": 900, **kw}  # fmt: skip
    return StudyConfig(**kw)


def _crossed(task) -> dict[str, set[str]]:
    """Person id -> the junctions whose crossings it walked on, SUMO running the task."""
    seen: dict[str, set[str]] = {}
    with Simulation(task.sim_config(), detect_collisions=False) as sim:
        while sim.time < task.sim_config().end_time - 1e-6:
            st = sim.step()
            for pid, lane in zip(st.ids.tolist(), st.lane.tolist(), strict=True):
                people = seen.setdefault(pid, set())
                if lane and lane.startswith(":") and "_c" in lane:
                    people.add(lane[1:].rsplit("_c", 1)[0])
    return seen


def test_auto_finds_the_maps_crossings(net):
    world = study_world(_config(map_net=str(net)))
    assert world.crossings == tuple(crossing_ids(net, walkable=True))
    assert len(world.crossings) >= 15 and f":{ZEBRA}_c0" in world.crossings
    assert {ZEBRA, SIGNAL} <= set(world.junctions)


def test_pedestrians_walk_across_the_chosen_crossings(net, tmp_path):
    chosen = (f":{ZEBRA}_c0", next(c for c in crossing_ids(net) if c.startswith(f":{SIGNAL}_")))
    (base, _sct) = build_inputs(_config(map_net=str(net), crossings=chosen), tmp_path)
    walkers = {p: j for p, j in _crossed(base).items() if p.startswith("ped") and j}
    assert len(walkers) > 10
    # every walker crossed at a chosen crossing's junction, and both are walked across
    assert set().union(*walkers.values()) == {ZEBRA, SIGNAL}
    result = run_arm(base)
    assert result.evaluated_steps > 0 and len(result.encounters) > 0


def test_study_inside_the_scenario_keeps_its_demand(scenario, tmp_path):
    config = _config(sumocfg=str(scenario), crossings=(f":{ZEBRA}_c0",))
    (base, _sct) = build_inputs(config, tmp_path)
    sim = base.sim_config()
    assert (sim.config, sim.begin, sim.end_time) == (scenario, BEGIN, BEGIN + RUN_S)
    seen = _crossed(base)
    # the scenario's flows and walkers, and the study's pedestrians at the zebra
    assert {p.split(".")[0] for p in seen if "." in p} >= {"east", "west", "south", "walk_e"}
    study = [j for p, j in seen.items() if p.startswith("ped") and j]
    assert study and all(j == {ZEBRA} for j in study)


def test_same_inputs_and_seed_same_results(scenario, tmp_path):
    config = _config(sumocfg=str(scenario), crossings=(f":{ZEBRA}_c0",), days=60 / 86400)
    (a, _), (b, _) = build_inputs(config, tmp_path / "a"), build_inputs(config, tmp_path / "b")
    assert a.routes.read_bytes() == b.routes.read_bytes()
    first, again = run_arm(a), run_arm(b)
    assert first.encounters == again.encounters
    assert np.array_equal(first.travel_time, again.travel_time) and len(first.travel_time) > 0


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--crossings", ":nope_c0"], "no pedestrian crossing ':nope_c0' (the net has 21: "),
        (["--crossings", "auto", "--variants", "both"], "--variants: applies to the generated"),
    ],
)
def test_bad_crossings_one_line_exit_1(net, tmp_path, capsys, args, words):
    out = tmp_path / "out"
    assert main(["study", "sct", "--map", str(net), *args, "-o", str(out), "-q"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("hiyari: error: ") and words in err and err.count("\n") == 1
    if "nope" in words:
        assert err.startswith(f"hiyari: error: {net}: ")
    assert not out.exists()


def test_bad_scenario_one_line_exit_1(scenario, tmp_path, capsys):
    bad = scenario.with_name("missing.sumocfg")
    bad.write_text(scenario.read_text().replace("walks.rou.xml", "gone.rou.xml"))
    out = tmp_path / "out"
    assert main(["study", "sct", "--sumocfg", str(bad), "-o", str(out), "-q"]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"hiyari: error: {bad}: route-files names ../in/route/gone.rou.xml")
    assert err.count("\n") == 1 and not out.exists()
    assert main(["study", "sct", "--sumocfg", str(scenario), "--vph", "100", "-o", str(out)]) == 1
    assert "--vph: in a SUMO scenario its own vehicles" in capsys.readouterr().err
    assert main(["study", "sct", "--crossings", "auto", "-o", str(out)]) == 1
    assert "--crossings: choose crossings on a map" in capsys.readouterr().err
    assert not out.exists()


def test_r157_judge_refuses_a_world(scenario, tmp_path, capsys):
    points = tmp_path / "points.csv"
    points.write_text("id\n")
    out = tmp_path / "out"
    assert main(["r157", "judge", str(points), "--sumocfg", str(scenario), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("hiyari: error: --sumocfg: an R157 test point is its Annex G")
    assert err.count("\n") == 1 and not out.exists()
