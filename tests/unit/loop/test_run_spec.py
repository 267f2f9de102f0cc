"""The run specification without SUMO: what result.json records of an ego setup, the one way
a user's stack factory is loaded, what SUMO is given for each kind of road, where a run
records, and a TOML file's runs counted and compiled."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from hiyari.bridge.loop.execute import RunOptions, chain
from hiyari.bridge.loop.spec import EgoSetup, Road, default_stack, load_stack, scenario_doc
from hiyari.bridge.loop.toml_runs import TomlPlan, preset_spec
from hiyari.bridge.openscenario.model.storyboard import Scenario, Storyboard
from hiyari.bridge.openscenario.presets.scenarios import World
from hiyari.bridge.openscenario.presets.toml_file import parse_scenario
from hiyari.errors import HiyariError
from hiyari.traffic.sumocfg import SumoScenario

GRID = {
    "scenario": {"type": "cut-in", "name": "grid", "seed": 5, "duration": 4.0},
    "ego": {"perception": "none", "aeb_delay": 0.5},
    "parameters": {"ve0_kmh": 72, "vo0_kmh": {"values": [20, 30, 40]}, "dx0_m": 20,
                   "vy_ms": {"range": [0.5, 1.0], "step": 0.5}},
}  # fmt: skip


def test_result_json_records_the_setup_without_seed_or_stack():
    """The setup's fields in their order after the scenario's (the seed earlier, the stack
    factory never: result.json stays as it was before the factory joined the setup)."""
    sc = Scenario("s", (), Storyboard((), ()), ego="Ego", parameters={"v": 1.5, "obj": object()})
    doc = scenario_doc(sc, EgoSetup(seed=7, stack=default_stack, set_speed=3.0))
    assert list(doc) == [
        "type", "name", "source", "road", "ego", "seed", "params", "perception", "sensors",
        "environment", "aeb_delay", "set_speed", "step_length", "max_duration",
    ]  # fmt: skip
    assert doc["seed"] == 7 and doc["set_speed"] == 3.0 and doc["params"] == {"v": 1.5}


def test_a_stack_factory_is_loaded_by_name_with_one_line_errors(tmp_path, monkeypatch):
    (tmp_path / "my_stack.py").write_text("def build(ctx):\n    return ctx\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert load_stack("my_stack:build", "ego.stack")("ctx") == "ctx"
    with pytest.raises(HiyariError, match=r"^--stack: cannot load 'my_stack:nope'"):
        load_stack("my_stack:nope", "--stack")
    with pytest.raises(HiyariError, match=r"^ego.stack: cannot load 'no_such_module:x'"):
        load_stack("no_such_module:x", "ego.stack")
    sys.modules.pop("my_stack", None)


def test_sumo_is_given_the_road_and_its_own_inputs_as_generated(tmp_path):
    ego = EgoSetup(step_length=0.1, seed=3)
    net, demand = tmp_path / "r.net.xml", tmp_path / "d.rou.xml"
    made = Road(net=net, routes=(demand,)).sim_config(net, ego, ("--x", "1"))
    assert (made.net, tuple(made.routes), made.step_length, made.seed) == (net, (demand,), 0.1, 3)
    assert tuple(made.generated) == (net, demand) and tuple(made.extra_args) == ("--x", "1")
    # a user's map: its load errors name the user's net, not hiyari's generated demand
    mapped = Road(net=net, routes=(demand,), user_net=True).sim_config(net, ego, ())
    assert tuple(mapped.generated) == (demand,)
    net.write_text("<net/>")
    cfg = tmp_path / "s.sumocfg"
    cfg.write_text('<configuration><input><net-file value="r.net.xml"/></input></configuration>')
    user = Road(net=net, sumo=SumoScenario(cfg, net)).sim_config(net, ego, ())
    assert user.config == cfg and user.step_length == 0.1 and user.seed == 3
    assert (
        not Road(net=net).has_demand() and Road(net=net, sumo=SumoScenario(cfg, net)).has_demand()
    )


def test_where_a_run_records():
    assert RunOptions().recording_path() is None
    assert RunOptions(out_dir=Path("o"), record=True).recording_path() == Path("o/run.mcap")
    assert RunOptions(recording=Path("r/x.mcap")).recording_path() == Path("r/x.mcap")
    with pytest.raises(HiyariError, match="recording needs an output folder"):
        RunOptions(record=True)
    calls: list[tuple[str, int]] = []
    both = chain(lambda x: calls.append(("a", x)), lambda x: calls.append(("b", x)))
    both(1)
    assert calls == [("a", 1), ("b", 1)] and chain(None, None) is None


def test_a_toml_files_runs_are_counted_overridden_and_compiled(tmp_path):
    plan = TomlPlan(parse_scenario(GRID, "grid.toml"), perception="perfect", environment="rain")
    assert plan.count() == 6 and plan.varied == ["vo0_kmh", "vy_ms"]
    assert plan.parameter_names == ["ve0_kmh", "vo0_kmh", "dx0_m", "vy_ms"]
    runs = plan.expand()
    assert [r.seed for r in runs] == [5, 6, 7, 8, 9, 10]
    assert runs[1].params == {"ve0_kmh": 72.0, "vo0_kmh": 20.0, "dx0_m": 20.0, "vy_ms": 1.0}
    spec = preset_spec(runs[1].scenario, tmp_path)
    ego = spec.ego
    assert (ego.perception, ego.environment, ego.aeb_delay, ego.seed) == ("perfect", "rain", 0.5, 6)
    assert ego.set_speed == pytest.approx(20.0) and ego.max_duration == 4.0 and ego.stack is None
    assert spec.label == runs[1].label() and spec.doc["index"] == 1
    assert spec.metadata["scenario"] == runs[1].label() and spec.metadata["step_length_s"] == 0.05
    assert spec.road.net.parent == tmp_path and spec.road.lanes is not None
    assert spec.scoring.target == "other" and not spec.road.has_demand()
    with pytest.raises(HiyariError, match="grid.toml: a cut-in scenario runs on its own road"):
        TomlPlan(parse_scenario(GRID, "grid.toml"), World(tmp_path / "map.net.xml"))
