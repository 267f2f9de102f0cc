"""RelativeClearanceCondition on SUMO: the lane to the ego's left ahead of it is clear until a
car standing there comes within the condition's forward distance; a car in the opposite
direction counts only when oppositeLanes is true."""

from __future__ import annotations

from pathlib import Path

from openscenario_files import (
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.bridge.openscenario.engine.measured import relative_lane

STOP = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="0"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def _clear(
    name: str, lanes: str, opposite: str, forward: float, backward: float, freespace: str = "false"
) -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Ego"/></TriggeringEntities>
<EntityCondition><RelativeClearanceCondition oppositeLanes="{opposite}" freeSpace="{freespace}" distanceForward="{forward}"
distanceBackward="{backward}">{lanes}</RelativeClearanceCondition></EntityCondition></ByEntityCondition></Condition>"""


def test_relative_lanes_count_left_in_the_direction_of_travel() -> None:
    assert relative_lane(-4, -3, 1.0) == 1 and relative_lane(-1, 1, 1.0) == 1
    assert relative_lane(2, 1, -1.0) == 1 and relative_lane(-1, 2, 1.0) == 2


def test_clearance_of_the_left_lane_and_the_opposite_one(tmp_path: Path) -> None:
    init = teleport_speed("Ego", -4, 50, 10) + teleport_speed("Car", -3, 100, 10)
    init += teleport_speed("Oncoming", 3, 300, 0)  # a lane of the other direction, standing
    stories = story("Car", STOP, time_condition(0.99, "stop", "none"), "Stop")
    left = '<RelativeLaneRange from="1" to="1"/>'
    never = '<Condition name="never" delay="0" conditionEdge="none"><ByValueCondition><SimulationTimeCondition value="1000" rule="greaterThan"/></ByValueCondition></Condition>'
    # in the stop trigger (always evaluated), each with a condition that never holds
    stop = "".join(
        f"<ConditionGroup>{c}{never}</ConditionGroup>"
        for c in (
            _clear("left", left, "false", 30.01, 10),
            _clear("any", "", "false", 250, 0),
            _clear("opp", "", "true", 250, 0),
        )
    )
    text = scenario_xml({"Ego": "", "Car": "", "Oncoming": ""}, init, stories, stop)
    states: dict[str, list[tuple[float, bool]]] = {"left": [], "any": [], "opp": []}

    def on_step(sim, world, report, engine) -> None:
        for i, c in enumerate(engine.bank.conditions):
            if c.name in states:
                states[c.name].append((round(report.time, 2), bool(engine.bank.static[i])))

    run_scenario(write(tmp_path / "c.xosc", text), tmp_path, until=7.5, on_step=on_step)
    # the car stops at s = 110 at t = 1; the ego (10 m/s from 50) is within 30 m of it at t = 3
    left = dict(states["left"])
    assert left[2.95] and not left[3.0] and not left[3.5]
    # the oncoming car 250 m ahead in lane 3: not in the ego's direction unless opposite lanes count
    assert dict(states["any"])[0.0] is False  # the car ahead in lane -3 is within 250 m
    assert dict(states["opp"])[0.0] is False
    # at 7 s the car is 10 m behind the ego; the oncoming one 180 m ahead (the other way)
    assert dict(states["any"])[7.0] is True and dict(states["opp"])[7.0] is False
