"""VariableDeclarations, VariableSetAction / VariableModifyAction, VariableCondition and the
deprecated ParameterSetAction / ParameterModifyAction, executed on SUMO: global actions run
once whatever the maneuver group's actors, conditions see a value from the step after the
action that set it, and a parameter changed at run time changes ParameterConditions only
(attributes were resolved when the file was read)."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    run_scenario,
    scenario_xml,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.errors import HiyariError

DT = 0.05


def _global(action: str) -> str:
    return f"<GlobalAction>{action}</GlobalAction>"


def _event(name: str, actions: list[str], condition: str, actor: str = "Car") -> str:
    body = "".join(f'<Action name="{name}{k}">{a}</Action>' for k, a in enumerate(actions))
    return f"""<Story name="{name}S"><Act name="{name}A"><ManeuverGroup maximumExecutionCount="1" name="{name}G">
<Actors selectTriggeringEntities="false"><EntityRef entityRef="{actor}"/></Actors>
<Maneuver name="{name}M"><Event name="{name}" priority="override">{body}
<StartTrigger><ConditionGroup>{condition}</ConditionGroup></StartTrigger></Event></Maneuver></ManeuverGroup>
<StartTrigger><ConditionGroup>{time_condition(0, name + "go", "none")}</ConditionGroup></StartTrigger></Act></Story>"""


def _value_condition(tag: str, ref: str, name: str, rule: str, value: str) -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="none"><ByValueCondition>
<{tag} {ref}="{name}" rule="{rule}" value="{value}"/></ByValueCondition></Condition>"""


def _with_variables(text: str, decls: str) -> str:
    return text.replace(
        "<CatalogLocations>",
        f"<VariableDeclarations>{decls}</VariableDeclarations><CatalogLocations>",
    )


STOP_CAR = (
    "<PrivateAction><LongitudinalAction><SpeedAction>"
    '<SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>'
    '<SpeedActionTarget><AbsoluteTargetSpeed value="$target"/></SpeedActionTarget>'
    "</SpeedAction></LongitudinalAction></PrivateAction>"
)


def test_variables_set_modify_and_trigger(tmp_path: Path) -> None:
    set_flag = _global(
        '<VariableAction variableRef="flag"><SetAction value="true"/></VariableAction>'
    )
    add2 = _global(
        '<VariableAction variableRef="count"><ModifyAction><Rule><AddValue value="2"/></Rule></ModifyAction></VariableAction>'
    )
    times3 = _global(
        '<VariableAction variableRef="count"><ModifyAction><Rule><MultiplyByValue value="3"/></Rule></ModifyAction></VariableAction>'
    )
    stories = _event("E1", [set_flag, add2], time_condition(0.99, "t1", "none"))
    stories += _event(
        "E2",
        [times3, STOP_CAR],
        _value_condition("VariableCondition", "variableRef", "flag", "equalTo", "true"),
    )
    stop = f"<ConditionGroup>{_value_condition('VariableCondition', 'variableRef', 'count', 'equalTo', '6')}</ConditionGroup>"
    text = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -1, 50, 10) + teleport_speed("Car", -1, 100, 10),
        stories,
        stop,
        params='<ParameterDeclaration name="target" parameterType="double" value="0"/>',
    )
    text = _with_variables(
        text,
        '<VariableDeclaration name="count" variableType="int" value="0"/>'
        '<VariableDeclaration name="flag" variableType="boolean" value="false"/>',
    )
    speeds: list[tuple[float, float]] = []
    engine, report = run_scenario(
        write(tmp_path / "v.xosc", text), tmp_path, until=5.0, dt=DT,
        on_step=lambda sim, w, r, e: speeds.append((r.time, e.actors["Car"].v)),
    )  # fmt: skip
    assert report.finished
    # E1 at 1.0 (flag, count 2); E2 sees flag at 1.05 (count 6); the stop trigger at 1.10
    assert report.time == pytest.approx(1.10)
    assert engine.values.get("variable", "count", "").text == "6"
    assert engine.values.get("variable", "flag", "").text == "true"
    started = [
        (t, n)
        for t, kind, n, tr in engine.tree.log
        if kind == "event" and tr == "startTransition" and n != "Init"
    ]
    assert [(round(t, 2), n) for t, n in started] == [(1.0, "E1"), (1.05, "E2")]
    at = {round(t, 2): v for t, v in speeds}
    assert at[1.0] == 10.0 and at[1.05] == 0.0  # the SpeedAction of E2 (a step) at 1.05


def test_deprecated_parameter_actions_change_conditions_not_attributes(tmp_path: Path) -> None:
    set_p = _global(
        '<ParameterAction parameterRef="target"><SetAction value="4"/></ParameterAction>'
    )
    add_p = _global(
        '<ParameterAction parameterRef="target"><ModifyAction><Rule><AddValue value="1.5"/></Rule></ModifyAction></ParameterAction>'
    )
    stories = _event("P1", [set_p], time_condition(0.49, "t1", "none"))
    stories += _event(
        "P2",
        [add_p, STOP_CAR],
        _value_condition("ParameterCondition", "parameterRef", "target", "greaterThan", "3"),
    )
    stop = f"<ConditionGroup>{_value_condition('ParameterCondition', 'parameterRef', 'target', 'equalTo', '5.5')}</ConditionGroup>"
    text = scenario_xml(
        {"Ego": "", "Car": ""},
        teleport_speed("Ego", -1, 50, 10) + teleport_speed("Car", -1, 100, 10),
        stories,
        stop,
        params='<ParameterDeclaration name="target" parameterType="double" value="1"/>',
    )
    engine, report = run_scenario(write(tmp_path / "p.xosc", text), tmp_path, until=3.0, dt=DT)
    assert report.time == pytest.approx(0.6)
    assert engine.values.get("parameter", "target", "").text == "5.5"
    # the SpeedAction's $target was 1 when the file was read
    assert engine.actors["Car"].v == 1.0


def test_undeclared_variable_is_one_line(tmp_path: Path) -> None:
    stop = f"<ConditionGroup>{_value_condition('VariableCondition', 'variableRef', 'nope', 'equalTo', '1')}</ConditionGroup>"
    text = scenario_xml({"Ego": ""}, teleport_speed("Ego", -1, 50, 10), stop=stop)
    with pytest.raises(
        HiyariError, match=r"v\.xosc:\d+: no variable 'nope' is declared \(declared: none\)"
    ):
        run_scenario(write(tmp_path / "v.xosc", text), tmp_path, until=1.0)
