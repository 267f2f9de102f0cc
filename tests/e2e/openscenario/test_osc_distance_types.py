"""DistanceCondition and TimeToCollisionCondition to a position by every relativeDistanceType
and coordinateSystem, with and without freespace, on SUMO: each event's start time against
the hand-derived step its condition first holds.

The car's reference point drives x = 50 + 10 t along lane -3 (y = -4.5) of the straight road,
its 5 x 2 m box centred 1.4 m ahead of it (front bumper at x + 3.9). The position is lane -5
(y = -11.5) at s = 150: 7 m to the car's right, its box 6 m. An update at time T sees the car
at x(T), so a condition first holding once x passes X fires at the first step after
(X - 50) / 10 s."""

from __future__ import annotations

from pathlib import Path

from openscenario_files import run_scenario, scenario_xml, teleport_speed, time_condition, write

DT = 0.05
POINT = '<Position><LanePosition roadId="0" laneId="-5" s="150"/></Position>'
NOOP = """<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="10"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>"""


def _distance(value: float, rule: str, fs: bool, system: str, dtype: str) -> str:
    return (
        f'<DistanceCondition value="{value}" freespace="{str(fs).lower()}" rule="{rule}" '
        f'coordinateSystem="{system}" relativeDistanceType="{dtype}">{POINT}</DistanceCondition>'
    )


def _ttc(value: float, fs: bool, system: str, dtype: str) -> str:
    return (
        f'<TimeToCollisionCondition value="{value}" freespace="{str(fs).lower()}" rule="lessThan" '
        f'coordinateSystem="{system}" relativeDistanceType="{dtype}">'
        f"<TimeToCollisionConditionTarget>{POINT}</TimeToCollisionConditionTarget>"
        "</TimeToCollisionCondition>"
    )


#: event name -> (condition, the time it first holds; None: never before 6 s)
CASES = {
    # 150 - x < 47.75 between reference points: x > 102.25, t > 5.225
    "lon_road": (_distance(47.75, "lessThan", False, "road", "longitudinal"), 5.25),
    "lon_lane": (_distance(47.75, "lessThan", False, "lane", "longitudinal"), 5.25),
    "lon_entity": (_distance(47.75, "lessThan", False, "entity", "longitudinal"), 5.25),
    # from the front bumper: 150 - (x + 3.9) < 47.75, x > 98.35, t > 4.835
    "lon_road_fs": (_distance(47.75, "lessThan", True, "road", "longitudinal"), 4.85),
    "lon_entity_fs": (_distance(47.75, "lessThan", True, "entity", "longitudinal"), 4.85),
    # euclidean between reference points: (150 - x)^2 + 7^2 < 47.75^2, x > 102.766
    "euclid_road": (_distance(47.75, "lessThan", False, "road", "euclidianDistance"), 5.3),
    "euclid_entity": (_distance(47.75, "lessThan", False, "entity", "euclidianDistance"), 5.3),
    # across: 7 m between reference points, 6 m from the box's side, from the start
    "lat_road_fs": (_distance(6.5, "lessThan", True, "road", "lateral"), 0.0),
    "lat_entity_fs": (_distance(6.5, "lessThan", True, "entity", "lateral"), 0.0),
    "lat_road": (_distance(6.5, "lessThan", False, "road", "lateral"), None),
    "lat_entity": (_distance(6.5, "greaterThan", False, "entity", "lateral"), 0.0),
    # closing at 10 m/s: (150 - (x + 3.9)) / 10 < 4.5, x > 101.1, t > 5.11
    "ttc_lon_fs": (_ttc(4.5, True, "road", "longitudinal"), 5.15),
    # between reference points: (150 - x) / 10 < 4.5, x > 105, t > 5.5
    "ttc_lon": (_ttc(4.5, False, "entity", "longitudinal"), 5.55),
    # nothing moves across the car's axis: no lateral closing, no TTC
    "ttc_lat": (_ttc(100.0, True, "entity", "lateral"), None),
}


def _condition(name: str, body: str) -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Car"/></TriggeringEntities>
<EntityCondition>{body}</EntityCondition></ByEntityCondition></Condition>"""


def test_distances_to_a_position_by_type_and_coordinate_system(tmp_path: Path) -> None:
    cases = {**CASES, "first": (None, 0.0)}
    events = "".join(
        f'<Event name="{n}" priority="parallel"><Action name="{n}A">{NOOP}</Action><StartTrigger>'
        f"<ConditionGroup>{time_condition(0, n, 'none') if n == 'first' else _condition(n, body)}"
        "</ConditionGroup></StartTrigger></Event>"
        for n, (body, _) in cases.items()
    )
    stories = f"""<Story name="S"><Act name="A"><ManeuverGroup maximumExecutionCount="1" name="G">
<Actors selectTriggeringEntities="false"><EntityRef entityRef="Car"/></Actors><Maneuver name="M">{events}</Maneuver></ManeuverGroup>
<StartTrigger><ConditionGroup>{time_condition(0, "go", "none")}</ConditionGroup></StartTrigger></Act></Story>"""
    stop = f"<ConditionGroup>{time_condition(6.0, 'end')}</ConditionGroup>"
    init = teleport_speed("Ego", -5, 20, 0) + teleport_speed("Car", -3, 50, 10)
    text = scenario_xml({"Ego": "", "Car": ""}, init, stories, stop)
    engine, report = run_scenario(write(tmp_path / "d.xosc", text), tmp_path, until=7.0, dt=DT)
    assert report.finished
    started = {
        n: round(t, 2)
        for t, kind, n, tr in engine.tree.log
        if kind == "event" and tr == "startTransition"
    }
    first = started["first"]  # the events' first evaluation
    want = {n: None if t is None else round(max(t, first), 2) for n, (_, t) in cases.items()}
    assert {n: started.get(n) for n in cases} == want
