"""OpenSCENARIO reader: the ALKS files with their catalogs and roads, parameters and
expressions against hand-computed values, parameter distributions, and bad input."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from openscenario_files import (
    ALKS,
    STRAIGHT,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.bridge.openscenario.model import (
    AbsoluteSpeed,
    ActivateControllerAction,
    DistanceType,
    Edge,
    EntityKind,
    LaneChangeAction,
    RelativeDistanceCondition,
    RelativeLanePosition,
    Shape,
    SpeedAction,
    TeleportAction,
)
from hiyari.bridge.openscenario.xosc.distributions import read_distribution
from hiyari.bridge.openscenario.xosc.expressions import evaluate
from hiyari.bridge.openscenario.xosc.reader import read_scenario
from hiyari.errors import HiyariError
from hiyari.traffic.actor_class import ActorClass

ALKS_FILES = sorted(ALKS.glob("alks_scenario_*.xosc"))


@pytest.mark.parametrize("path", ALKS_FILES, ids=lambda p: p.stem[14:19])
def test_every_alks_scenario_reads_with_catalogs_and_road(path: Path) -> None:
    sc = read_scenario(path)
    assert sc.ego == "Ego"
    ego = sc.entity("Ego")
    assert (ego.length, ego.width, ego.height, ego.centre) == (5.0, 2.0, 1.8, (1.4, 0.0, 0.9))
    assert ego.controller is not None and ego.controller.name == "ALKSController"
    assert sc.road_network is not None and sc.road_network.is_file()
    assert sc.road_network.parent == ALKS / "road_networks"
    acts = [a.action.body for a in sc.storyboard.init if a.entity == "Ego"]
    assert isinstance(acts[0], TeleportAction)
    assert isinstance(acts[1], SpeedAction) and acts[1].target == AbsoluteSpeed(60.0 / 3.6)


def test_cut_in_values_and_structure_match_the_file() -> None:
    sc = read_scenario(ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc")
    cut_in = sc.entity("CutInVehicle")
    assert cut_in.kind == EntityKind.VEHICLE and cut_in.actor_class == ActorClass.CAR
    init = {(a.entity, type(a.action.body).__name__): a.action.body for a in sc.storyboard.init}
    pos = init[("CutInVehicle", "TeleportAction")].position
    # ds = dx0 + (-10 s * relative speed / 3.6) = 30 + 10 * 20 / 3.6
    assert isinstance(pos, RelativeLanePosition)
    assert pos.ds == pytest.approx(30.0 + 200.0 / 3.6, abs=1e-12) and pos.d_lane == -1
    story_ = next(s for s in sc.storyboard.stories if s.name == "CutInStory")
    event = story_.acts[0].groups[0].maneuvers[0].events[0]
    lc = event.actions[0].body
    assert isinstance(lc, LaneChangeAction) and lc.dynamics.shape == Shape.SINUSOIDAL
    assert lc.dynamics.value == 2.0
    cond = event.start_trigger[0][0]
    assert cond.edge == Edge.RISING
    assert isinstance(cond.body.body, RelativeDistanceCondition)
    assert cond.body.body.distance_type == DistanceType.LONGITUDINAL and cond.body.body.freespace
    activate = sc.storyboard.stories[0].acts[0].groups[0].maneuvers[0].events[0].actions[0].body
    assert activate == ActivateControllerAction(lateral=True, longitudinal=True)
    assert sc.storyboard.stop_trigger[0][0].delay == 10.0


def test_parameters_override_and_constraints() -> None:
    path = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
    sc = read_scenario(path, {"CutInVehicle_HeadwayDistanceTrigger_dx0_m": 12.5})
    init = {(a.entity, type(a.action.body).__name__): a.action.body for a in sc.storyboard.init}
    assert init[("CutInVehicle", "TeleportAction")].position.ds == pytest.approx(12.5 + 200 / 3.6)
    with pytest.raises(HiyariError, match=r"Ego_InitSpeed_Ve0_kph = 80.0 violates"):
        read_scenario(path, {"Ego_InitSpeed_Ve0_kph": 80.0})
    with pytest.raises(HiyariError, match="no parameter Nope is declared"):
        read_scenario(path, {"Nope": 1})


def test_expressions_follow_the_standard() -> None:
    p = {"a": "60.0", "b": "-5", "s": "car", "t": "true"}.__getitem__
    assert evaluate("$a / 3.6", p) == pytest.approx(16.666666666666668)
    assert evaluate("2 * sqrt($b * $b) / (5 / 3.6)", p) == pytest.approx(7.2)
    assert evaluate("-$b + 7 % 3 * 2", p) == 7.0
    assert (
        evaluate("pow(2, 10) - round(2.5) + round(-2.5) + floor(-1.5) + ceil(1.2)", p)
        == 1024 - 3 - 3 - 2 + 2
    )
    assert evaluate("-(1 + 2) * -2", p) == 6.0
    assert evaluate("1 < 2 and not false or $t == 0", p) is True
    for bad in ("1 +", "$zz", "absolute(1)", "1 / 0", "$s * 2", "(1", "sqrt(-1)", "pow(1)"):
        with pytest.raises(ValueError):
            evaluate(bad, p)


def test_distribution_deterministic_product(tmp_path: Path) -> None:
    scenario = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
    text = f"""<?xml version="1.0"?>
<OpenSCENARIO><FileHeader revMajor="1" revMinor="3" date="2026-01-01T00:00:00" description="d" author="t"/>
<ParameterValueDistribution><ScenarioFile filepath="{scenario}"/><Deterministic>
<DeterministicSingleParameterDistribution parameterName="Ego_InitSpeed_Ve0_kph">
<DistributionRange stepWidth="10"><Range lowerLimit="30" upperLimit="60"/></DistributionRange>
</DeterministicSingleParameterDistribution>
<DeterministicMultiParameterDistribution><ValueSetDistribution>
<ParameterValueSet><ParameterAssignment parameterRef="CutInVehicle_Model" value="car"/><ParameterAssignment parameterRef="CutInVehicle_InitPosition_RelativeLaneId" value="-1"/></ParameterValueSet>
<ParameterValueSet><ParameterAssignment parameterRef="CutInVehicle_Model" value="truck"/><ParameterAssignment parameterRef="CutInVehicle_InitPosition_RelativeLaneId" value="1"/></ParameterValueSet>
</ValueSetDistribution></DeterministicMultiParameterDistribution>
<DeterministicSingleParameterDistribution parameterName="CutInVehicle_HeadwayDistanceTrigger_dx0_m">
<DistributionSet><Element value="10"/><Element value="30"/></DistributionSet>
</DeterministicSingleParameterDistribution>
</Deterministic></ParameterValueDistribution></OpenSCENARIO>"""
    d = read_distribution(write(tmp_path / "d.xosc", text))
    assert d.scenario == scenario.resolve()
    assert len(d.runs) == 4 * 2 * 2
    speeds = sorted({float(r["Ego_InitSpeed_Ve0_kph"]) for r in d.runs})
    assert speeds == [30.0, 40.0, 50.0, 60.0]
    assert {
        (r["CutInVehicle_Model"], r["CutInVehicle_InitPosition_RelativeLaneId"]) for r in d.runs
    } == {
        ("car", "-1"),
        ("truck", "1"),
    }
    assert d.runs[0] == {
        "Ego_InitSpeed_Ve0_kph": "30.0",
        "CutInVehicle_Model": "car",
        "CutInVehicle_InitPosition_RelativeLaneId": "-1",
        "CutInVehicle_HeadwayDistanceTrigger_dx0_m": "10",
    }
    for run in d.runs:  # every run is a readable scenario (constraints hold)
        sc = read_scenario(d.scenario, run)
        assert sc.parameters["CutInVehicle_Model"] == run["CutInVehicle_Model"]
        assert sc.entity("CutInVehicle").length == (
            18.75 if run["CutInVehicle_Model"] == "truck" else 5.0
        )


def test_distribution_stochastic_is_seeded_and_in_range(tmp_path: Path) -> None:
    scenario = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
    text = f"""<?xml version="1.0"?>
<OpenSCENARIO><FileHeader revMajor="1" revMinor="3" date="2026-01-01T00:00:00" description="d" author="t"/>
<ParameterValueDistribution><ScenarioFile filepath="{scenario}"/><Stochastic numberOfTestRuns="200">
<StochasticDistribution parameterName="Ego_InitSpeed_Ve0_kph"><UniformDistribution><Range lowerLimit="30" upperLimit="60"/></UniformDistribution></StochasticDistribution>
<StochasticDistribution parameterName="CutInVehicle_HeadwayDistanceTrigger_dx0_m"><NormalDistribution expectedValue="30" variance="25"><Range lowerLimit="25" upperLimit="40"/></NormalDistribution></StochasticDistribution>
<StochasticDistribution parameterName="CutInVehicle_Model"><ProbabilityDistributionSet><Element value="car" weight="3"/><Element value="truck" weight="1"/></ProbabilityDistributionSet></StochasticDistribution>
</Stochastic></ParameterValueDistribution></OpenSCENARIO>"""
    path = write(tmp_path / "s.xosc", text)
    with pytest.raises(HiyariError, match="give a seed"):
        read_distribution(path)
    a, b, c = read_distribution(path, 7), read_distribution(path, 7), read_distribution(path, 8)
    assert a.runs == b.runs and a.runs != c.runs and len(a.runs) == 200
    v = np.array([float(r["Ego_InitSpeed_Ve0_kph"]) for r in a.runs])
    dx = np.array([float(r["CutInVehicle_HeadwayDistanceTrigger_dx0_m"]) for r in a.runs])
    assert v.min() >= 30 and v.max() <= 60 and dx.min() >= 25 and dx.max() <= 40
    assert abs(np.median(dx) - 30.0) < 1.5  # truncated normal about 30 with sigma 5
    trucks = sum(r["CutInVehicle_Model"] == "truck" for r in a.runs) / len(a.runs)
    assert 0.15 < trucks < 0.35


# ---------------------------------------------------------------------------- bad input
def _one_line(exc: pytest.ExceptionInfo) -> str:
    msg = str(exc.value)
    assert "\n" not in msg
    return msg


def test_schema_invalid_file_names_file_and_line(tmp_path: Path) -> None:
    xml = scenario_xml({"Ego": ""}, teleport_speed("Ego", -4, 5.0, 10.0)).replace(
        '<SpeedActionDynamics dynamicsShape="step"', '<SpeedActionDynamics dynamicsShape="wobbly"'
    )
    path = write(tmp_path / "bad.xosc", xml)
    with pytest.raises(HiyariError) as exc:
        read_scenario(path)
    line = xml[: xml.index("wobbly")].count("\n") + 1
    assert _one_line(exc).startswith(f"{path}:{line}: not valid OpenSCENARIO 1.3")


def test_unknown_parameter_missing_catalog_and_road(tmp_path: Path) -> None:
    xml = scenario_xml({"Ego": ""}, teleport_speed("Ego", -4, "$Nowhere", 10.0))
    path = write(tmp_path / "p.xosc", xml)
    with pytest.raises(HiyariError) as exc:
        read_scenario(path)
    line = xml[: xml.index("$Nowhere")].count("\n") + 1
    assert _one_line(exc) == f"{path}:{line}: unknown parameter $Nowhere"

    ref = '<CatalogReference catalogName="vehicle_catalog" entryName="car"/>'
    xml = scenario_xml(
        {"Ego": ref}, teleport_speed("Ego", -4, 5.0, 10.0),
        catalogs='<VehicleCatalog><Directory path="./no_such_dir"/></VehicleCatalog>',
    )  # fmt: skip
    with pytest.raises(HiyariError) as exc:
        read_scenario(write(tmp_path / "c.xosc", xml))
    msg = _one_line(exc)
    assert "catalog 'vehicle_catalog' not found" in msg and "no_such_dir" in msg

    xml = scenario_xml(
        {"Ego": ""}, teleport_speed("Ego", -4, 5.0, 10.0), road=tmp_path / "gone.xodr"
    )
    with pytest.raises(HiyariError) as exc:
        read_scenario(write(tmp_path / "r.xosc", xml))
    assert "road network file" in _one_line(exc) and "gone.xodr not found" in str(exc.value)


def test_unsupported_element_names_element_line_and_file(tmp_path: Path) -> None:
    custom = '<UserDefinedAction><CustomCommandAction type="kick">now</CustomCommandAction></UserDefinedAction>'
    xml = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -4, 5.0, 10.0) + teleport_speed("Car", -3, 5.0, 10.0),
        story("Car", "MARK", time_condition(1.0)),
    ).replace("<PrivateAction>MARK</PrivateAction>", custom)
    path = write(tmp_path / "u.xosc", xml)
    with pytest.raises(HiyariError) as exc:
        read_scenario(path)
    line = xml[: xml.index("<UserDefinedAction")].count("\n") + 1
    assert _one_line(exc) == (
        f"{path}:{line}: <UserDefinedAction> is not supported by hiyari (a custom command means "
        "something only to the tool it was written for)"
    )


def test_deprecated_1_0_constructs_read(tmp_path: Path) -> None:
    """A 1.0-style file: priority overwrite, ReachPositionCondition, alongRoute."""
    reach = """<Condition name="r" delay="0" conditionEdge="rising"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Ego"/></TriggeringEntities>
<EntityCondition><ReachPositionCondition tolerance="2.0"><Position><LanePosition roadId="0" laneId="-4" s="100" offset="0"/></Position></ReachPositionCondition></EntityCondition>
</ByEntityCondition></Condition>
<Condition name="h" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Ego"/></TriggeringEntities>
<EntityCondition><TimeHeadwayCondition entityRef="Car" value="3" freespace="false" alongRoute="true" rule="lessThan"/></EntityCondition>
</ByEntityCondition></Condition>"""
    speed = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="5"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""
    xml = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -4, 5.0, 10.0) + teleport_speed("Car", -4, 50.0, 10.0),
        story("Car", speed, reach).replace('priority="override"', 'priority="overwrite"'),
        rev=0,
    )
    sc = read_scenario(write(tmp_path / "old.xosc", xml))
    event = sc.storyboard.stories[0].acts[0].groups[0].maneuvers[0].events[0]
    assert event.priority == "override"
    kinds = [type(c.body.body).__name__ for c in event.start_trigger[0]]
    assert kinds == ["ReachPositionCondition", "TimeHeadwayCondition"]
    assert event.start_trigger[0][1].body.body.coordinate_system == "road"
    assert math.isclose(event.start_trigger[0][0].body.body.tolerance, 2.0)


def test_alks_files_also_pass_the_strict_schema() -> None:
    from lxml import etree

    strict = etree.XMLSchema(etree.parse(str(ALKS.parent / "schema" / "OpenSCENARIO_1_3.xsd")))
    assert all(strict.validate(etree.parse(str(p))) for p in ALKS_FILES)
    assert STRAIGHT.is_file()
