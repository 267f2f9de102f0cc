"""CollisionCondition ByType: a car driving into a standing pedestrian is in contact with a
pedestrian (not with a vehicle) from the step the outlines overlap."""

from __future__ import annotations

from pathlib import Path

from openscenario_files import run_scenario, scenario_xml, story, teleport_speed, write

PED = """<Pedestrian name="p" mass="70" model="m" pedestrianCategory="pedestrian"><BoundingBox><Center x="0" y="0" z="0.9"/>
<Dimensions width="0.5" length="0.5" height="1.8"/></BoundingBox><Properties/></Pedestrian>"""
NOOP = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="10"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def _hit(kind: str, name: str) -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="rising"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Car"/></TriggeringEntities>
<EntityCondition><CollisionCondition><ByType type="{kind}"/></CollisionCondition></EntityCondition></ByEntityCondition></Condition>"""


def test_collision_with_a_pedestrian_by_type(tmp_path: Path) -> None:
    init = (
        teleport_speed("Ego", -5, 20, 10)
        + teleport_speed("Car", -3, 50, 10)
        + teleport_speed("Ped", -3, 80, 0)
    )
    stories = story("Car", NOOP, _hit("pedestrian", "ped"), "Ped") + story(
        "Car", NOOP, _hit("vehicle", "veh"), "Veh"
    )
    engine, _ = run_scenario(
        write(tmp_path / "c.xosc", scenario_xml({"Ego": "", "Car": "", "Ped": PED}, init, stories)),
        tmp_path,
        until=4.0,
    )
    started = {
        n: t for t, kind, n, tr in engine.tree.log if kind == "event" and tr == "startTransition"
    }
    # the car's front (1.4 + 2.5 m ahead of its reference at 50) meets the pedestrian's back
    # (0.25 m behind 80) after 26.35 m: at 2.635 s, seen from the step after (2.65 s)
    assert abs(started["PedE"] - 2.65) <= 0.051
    assert "VehE" not in started
