"""Known deviations from the OpenSCENARIO 1.3 schema (what esmini's examples and catalogs
write) are repaired in the parsed tree with exactly one warning line each, naming the file and
line; each file here is refused by the schema as written; a catalog file nobody references
blocks nothing; --ego picks the ego of a file with none of the names hiyari recognises."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest
from lxml import etree
from openscenario_files import CAR, scenario_xml, story, teleport_speed, time_condition, write

from hiyari.bridge.loop.xosc_runs import load_plan
from hiyari.bridge.openscenario.model import SpeedAction
from hiyari.bridge.openscenario.model.conditions import CoordinateSystem
from hiyari.bridge.openscenario.xosc import document
from hiyari.bridge.openscenario.xosc.reader import read_scenario
from hiyari.errors import HiyariError

SPEED = """<PrivateAction><LongitudinalAction><SpeedAction>{dyn}
<SpeedActionTarget><AbsoluteTargetSpeed value="{v}"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>"""
PLACE = """<PrivateAction><TeleportAction><Position><LanePosition roadId="0" laneId="-1" offset="0" s="50"/></Position></TeleportAction></PrivateAction>"""


def _line(text: str, needle: str) -> int:
    """The 1-based line of the first line of ``text`` holding ``needle``."""
    return next(k for k, ln in enumerate(text.splitlines(), 1) if needle in ln)


def _schema_refuses(path: Path) -> bool:
    tree = etree.parse(str(path), etree.XMLParser(remove_comments=True))
    return not document._schema().validate(tree)


def _read(tmp_path: Path, text: str, caplog: pytest.LogCaptureFixture):
    """The scenario ``text`` read, its file, and the repair warnings; the file is refused
    without the repairs (schema or reader)."""
    path = write(tmp_path / "s.xosc", text).resolve()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(document, "repair", lambda root: [])
        with pytest.raises(HiyariError):
            read_scenario(path)
    with caplog.at_level(logging.WARNING):
        sc = read_scenario(path)
    lines = [r.getMessage() for r in caplog.records if r.name.endswith("xosc.document")]
    return sc, path, lines


def _action(v: float) -> str:
    """A step SpeedAction to ``v`` m/s, the body of a PrivateAction."""
    dyn = '<SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>'
    return SPEED.format(dyn=dyn, v=v)[len("<PrivateAction>") : -len("</PrivateAction>")]


def _ego_init_speed(sc) -> SpeedAction:
    return next(
        a.action.body
        for a in sc.storyboard.init
        if a.entity == "Ego" and isinstance(a.action.body, SpeedAction)
    )


def test_dollar_declaration_name(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    params = '<ParameterDeclaration name="$Speed" parameterType="double" value="7"/>'
    dyn = '<SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>'
    init = f'<Private entityRef="Ego">{PLACE}{SPEED.format(dyn=dyn, v="$Speed")}</Private>'
    text = scenario_xml({"Ego": ""}, init, params=params)
    sc, path, lines = _read(tmp_path, text, caplog)
    n = _line(text, 'name="$Speed"')
    assert lines == [
        f'{path}:{n}: <ParameterDeclaration name="$Speed">: declared as Speed (the leading $ '
        "removed)"
    ]
    assert _ego_init_speed(sc).target.value == 7.0


def test_negative_rate_and_step_without_value(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    neg = '<SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="rate" value="-2.5"/>'
    init = f'<Private entityRef="Ego">{PLACE}{SPEED.format(dyn=neg, v=20)}</Private>'
    step = SPEED.format(dyn='<SpeedActionDynamics dynamicsShape="step"/>', v=3)
    text = scenario_xml({"Ego": "", "A": ""}, init + teleport_speed("A", -1, 90, 10),
                        story("A", step[len("<PrivateAction>") : -len("</PrivateAction>")],
                              time_condition(1)))  # fmt: skip
    sc, path, lines = _read(tmp_path, text, caplog)
    neg_line, step_line = _line(text, 'value="-2.5"'), _line(text, 'dynamicsShape="step"/>')
    assert lines == [
        f'{path}:{neg_line}: <SpeedActionDynamics dynamicsDimension="rate" '
        'value="-2.5">: negative value read as 2.5',
        f"{path}:{step_line}: <SpeedActionDynamics "
        'dynamicsShape="step">: value="0", dynamicsDimension="time" added (a step takes no time)',
    ]
    assert _ego_init_speed(sc).dynamics.value == 2.5
    a_speed = sc.storyboard.stories[0].acts[0].groups[0].maneuvers[0].events[0].actions[0].body
    assert a_speed.dynamics.value == 0.0 and a_speed.target.value == 3.0


def test_capitalised_booleans_and_bool_type(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    params = '<ParameterDeclaration name="Flag" parameterType="bool" value="True"/>'
    body = story("Ego", _action(3), time_condition(1)).replace(
        'selectTriggeringEntities="false"', 'selectTriggeringEntities="False"'
    )
    text = scenario_xml({"Ego": ""}, teleport_speed("Ego", -1, 50, 10), body, params=params)
    sc, path, lines = _read(tmp_path, text, caplog)
    p, a = _line(text, 'name="Flag"'), _line(text, 'selectTriggeringEntities="False"')
    assert lines == [
        f'{path}:{p}: <ParameterDeclaration name="Flag" parameterType="bool">: read as '
        'parameterType="boolean"',
        f'{path}:{a}: <Actors selectTriggeringEntities="False">: read as '
        'selectTriggeringEntities="false"',
        f'{path}:{p}: <ParameterDeclaration name="Flag" value="True">: read as value="true"',
    ]
    assert sc.parameters["Flag"] == "true"
    assert sc.storyboard.stories[0].acts[0].groups[0].select_triggering is False


def test_missing_condition_edge_and_the_old_edge_name(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    body = story("A", _action(3), time_condition(2, "late").replace(' conditionEdge="rising"', ""))
    stop = time_condition(9, "end").replace("conditionEdge", "edge")
    init = teleport_speed("Ego", -1, 50, 10) + teleport_speed("A", -1, 90, 10)
    text = scenario_xml(
        {"Ego": "", "A": ""}, init, body, f"<ConditionGroup>{stop}</ConditionGroup>"
    )
    sc, path, lines = _read(tmp_path, text, caplog)
    late, end = _line(text, 'name="late"'), _line(text, 'name="end"')
    assert lines == [
        f'{path}:{late}: <Condition name="late">: no conditionEdge: conditionEdge="none"',
        f'{path}:{end}: <Condition name="end">: edge="rising" read as conditionEdge="rising"',
    ]
    ev = sc.storyboard.stories[0].acts[0].groups[0].maneuvers[0].events[0]
    assert ev.start_trigger[0][0].edge.value == "none"
    assert sc.storyboard.stop_trigger[0][0].edge.value == "rising"


CATALOG = """<?xml version="1.0" encoding="utf-8"?>
<OpenSCENARIO>
<FileHeader revMajor="1" revMinor="3" date="2026-01-01T00:00:00" author="t"/>
<Catalog name="Cars">
<Vehicle name="car" vehicleCategory="car">
  <ParameterDeclarations><ParameterDeclaration name="Length" parameterType="double" value="5"/></ParameterDeclarations>
  <BoundingBox><Center x="1.4" y="0" z="0.9"/><Dimensions width="2.0" length="$Length" height="1.8"/></BoundingBox>
  <Performance maxSpeed="70" maxDeceleration="10" maxAcceleration="10"/>
  <Axles><FrontAxle maxSteering="0.5" wheelDiameter="0.8" trackWidth="1.68" positionX="2.98" positionZ="0.4"/>
  <RearAxle maxSteering="0" wheelDiameter="0.8" trackWidth="1.68" positionX="0" positionZ="0.4"/></Axles>
  <Properties/>
  <Trailer><EntityRef entityRef="$TrailerRef"/></Trailer>
</Vehicle>
</Catalog>
</OpenSCENARIO>
"""
REF = """<CatalogReference catalogName="{cat}" entryName="car"><ParameterAssignments>
<ParameterAssignment parameterRef="$Length" value="4.2"/></ParameterAssignments></CatalogReference>"""


def _with_catalog(tmp_path: Path, cat: str = "Cars") -> tuple[str, Path]:
    cats = tmp_path / "cats"
    cats.mkdir()
    catalog = write(cats / "cars.xosc", CATALOG).resolve()
    loc = f'<VehicleCatalog><Directory path="{cats}"/></VehicleCatalog>'
    init = teleport_speed("Ego", -1, 50, 10)
    return scenario_xml({"Ego": REF.format(cat=cat)}, init, catalogs=loc), catalog


def test_catalog_trailer_reference_header_and_dollar_parameter_ref(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    text, catalog = _with_catalog(tmp_path)
    assert _schema_refuses(catalog)
    sc, path, lines = _read(tmp_path, text, caplog)
    assert lines == [
        f'{path}:{_line(text, "parameterRef")}: <ParameterAssignment parameterRef="$Length">: '
        "names Length (the leading $ removed)",
        f'{catalog}:{_line(CATALOG, "<Trailer>")}: <Vehicle name="car"> <Trailer><EntityRef '
        'entityRef="$TrailerRef"/>: pre-1.3 trailer reference dropped: the trailer is ignored',
        f'{catalog}:3: <FileHeader>: no description: description="" added',
    ]
    assert sc.entity("Ego").length == 4.2


def test_an_unreferenced_bad_catalog_file_blocks_nothing(tmp_path: Path) -> None:
    text, catalog = _with_catalog(tmp_path)
    bad = CATALOG.replace('name="Cars"', 'name="Broken"').replace('"car"', '"hovercraft"')
    write(catalog.parent / "broken.xosc", bad)
    write(catalog.parent / "garbage.xosc", "<OpenSCENARIO><FileHeader")
    path = write(tmp_path / "s.xosc", text)
    assert read_scenario(path).entity("Ego").length == 4.2
    # referenced, the bad file is refused in one line naming it
    write(path, text.replace('catalogName="Cars"', 'catalogName="Broken"'))
    with pytest.raises(HiyariError, match=r"broken\.xosc:\d+: not valid OpenSCENARIO 1\.3"):
        read_scenario(path)
    write(path, text.replace('catalogName="Cars"', 'catalogName="Nope"'))
    with pytest.raises(HiyariError, match=r"not readable as catalogs: garbage\.xosc"):
        read_scenario(path)


def test_ego_option_names_the_ego(tmp_path: Path) -> None:
    init = teleport_speed("Car1", -1, 50, 10) + teleport_speed("Car2", -1, 90, 10)
    path = write(tmp_path / "s.xosc", scenario_xml({"Car1": "", "Car2": ""}, init)).resolve()
    with pytest.raises(HiyariError) as exc:
        load_plan(path)
    assert str(exc.value) == (
        f"{path}: the scenario has no ego: no entity has the property type=ego_vehicle or is "
        "named ego / hero (entities: Car1, Car2); name the ego with --ego NAME"
    )
    (run,) = load_plan(path, ego="Car2").expand()
    assert run.load().ego == "Car2"
    with pytest.raises(HiyariError, match=r"--ego Car3: no such entity \(entities: Car1, Car2\)"):
        load_plan(path, ego="Car3")


def test_a_valid_file_has_no_repairs(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    text = scenario_xml({"Ego": CAR.format(name="Ego")}, teleport_speed("Ego", -1, 50, 10))
    path = write(tmp_path / "s.xosc", text)
    with caplog.at_level(logging.WARNING):
        read_scenario(path)
    assert not [r for r in caplog.records if r.name.endswith("xosc.document")]


def test_catalog_header_date_and_property_among_declarations(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    text, catalog = _with_catalog(tmp_path)
    odd = CATALOG.replace("2026-01-01T00:00:00", "2020-10-204T10:00:00").replace(
        "<ParameterDeclarations>", '<ParameterDeclarations><Property name="p" value="1"/>'
    )
    write(catalog, odd)
    assert _schema_refuses(catalog)
    sc, path, lines = _read(tmp_path, text, caplog)
    assert lines[-2:] == [
        f'{catalog}:3: <FileHeader date="2020-10-204T10:00:00">: not a date and time: read as '
        "1970-01-01T00:00:00 (the header's date is not used)",
        f'{catalog}:{_line(odd, "<Property ")}: <Vehicle name="car"> <Property name="p">: '
        "inside ParameterDeclarations: moved to the Properties",
    ]
    assert sc.entity("Ego").properties == {"p": "1"}


def test_world_coordinate_system_is_read(tmp_path: Path) -> None:
    angle = """<Condition name="a" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Ego"/></TriggeringEntities>
<EntityCondition><AngleCondition angleType="heading" angle="0" angleTolerance="0.1" coordinateSystem="world"/>
</EntityCondition></ByEntityCondition></Condition>"""
    init = teleport_speed("Ego", -1, 50, 10)
    text = scenario_xml({"Ego": ""}, init, stop=f"<ConditionGroup>{angle}</ConditionGroup>")
    sc = read_scenario(write(tmp_path / "s.xosc", text))
    ((condition,),) = sc.storyboard.stop_trigger
    assert condition.body.body.coordinate_system == CoordinateSystem.WORLD


def test_unnamed_story_and_maneuver(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    # esmini's straight_500m.xosc writes <Story> and alks_cut-in.xosc <Maneuver> without name
    body = story("Ego", _action(12), time_condition(1.0), "S")
    body = body.replace('<Story name="S">', "<Story>").replace('<Maneuver name="SM">', "<Maneuver>")
    text = scenario_xml({"Ego": CAR.format(name="Ego")}, teleport_speed("Ego", -1, 50, 10), body)
    sc, path, lines = _read(tmp_path, text, caplog)
    story_line, man_line = _line(text, "<Story>"), _line(text, "<Maneuver>")
    assert lines == [
        f'{path}:{story_line}: <Story>: no name: named "unnamed Story at line {story_line}" '
        "(nothing can refer to it)",
        f'{path}:{man_line}: <Maneuver>: no name: named "unnamed Maneuver at line {man_line}" '
        "(nothing can refer to it)",
    ]
    st = sc.storyboard.stories[0]
    assert st.name == f"unnamed Story at line {story_line}"
    assert st.acts[0].groups[0].maneuvers[0].name == f"unnamed Maneuver at line {man_line}"
