"""Distances along the road network across roads, on the town map of tests/support/
xodr_authoring (road 1: x 0..100, connecting road 101: x 100..120, road 2: x 120..220, all
straight along x, lane -2 at y = -2.25): a LongitudinalDistanceAction whose gap reaches back
past the reference's road start puts the actor on the road before it, and lane-frame
RelativeDistanceConditions measure between entities on different roads along the links."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import run_scenario, scenario_xml, story, time_condition, write
from xodr_authoring import TOWN, opendrive, road, town_map
from xodr_authoring import write as write_xodr

KEEP = """<LongitudinalAction><LongitudinalDistanceAction entityRef="Lead" distance="30" freespace="false"
continuous="true" displacement="trailingReferencedEntity" coordinateSystem="road"/></LongitudinalAction>"""
NOOP = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="0"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def _place(entity: str, road: int, s: float, speed: float) -> str:
    return f"""<Private entityRef="{entity}">
<PrivateAction><TeleportAction><Position><LanePosition roadId="{road}" laneId="-2" offset="0" s="{s}"/></Position></TeleportAction></PrivateAction>
<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="{speed}"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>
</Private>"""


def _lane_distance(name: str, value: float, rule: str, system: str = "lane") -> str:
    return f"""<Condition name="{name}" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Follow"/></TriggeringEntities>
<EntityCondition><RelativeDistanceCondition entityRef="Lead" freespace="false" relativeDistanceType="longitudinal"
coordinateSystem="{system}" value="{value}" rule="{rule}"/></EntityCondition></ByEntityCondition></Condition>"""


def test_gap_and_lane_distance_across_a_junction(tmp_path: Path) -> None:
    # the lead at road 2 s = 10 (x = 130) driving 10 m/s; the follower put 30 m behind it
    # along the links: road 2 s 10 -> 0, connecting road 101 s 20 -> 0 (x = 100), then on
    # x = lead x - 30 every step: through road 101 and onto road 2 at x 120 (t = 1 s)
    init = _place("Ego", 1, 10, 0) + _place("Lead", 2, 10, 10) + _place("Follow", 1, 50, 10)
    init += f'<Private entityRef="Follow"><PrivateAction>{KEEP}</PrivateAction></Private>'
    # lane frame, Follow to Lead: 30 m along the links (not measured before: the conditions
    # wait for t >= 0.1); 29.9 < 30 < 30.1
    stories = story(
        "Ego",
        NOOP,
        time_condition(0.1, "a", "none") + _lane_distance("near", 30.1, "lessThan"),
        "Near",
    )
    stories += story(
        "Ego",
        NOOP,
        time_condition(0.1, "b", "none") + _lane_distance("far", 29.9, "lessThan"),
        "Far",
    )
    # the same in road coordinates (the trigger kernel's road frame)
    for name, value in (("RNear", 30.1), ("RFar", 29.9)):
        stories += story(
            "Ego",
            NOOP,
            time_condition(0.1, name + "t", "none")
            + _lane_distance(name + "c", value, "lessThan", "road"),
            name,
        )
    text = scenario_xml({"Ego": "", "Lead": "", "Follow": ""}, init, stories,
                        f"<ConditionGroup>{time_condition(2.0, 'end')}</ConditionGroup>",
                        road=town_map(tmp_path / "town.xodr"))  # fmt: skip
    seen = []

    def on_step(sim, world, report, engine) -> None:
        lead, fol = engine.actors["Lead"], engine.actors["Follow"]
        seen.append((report.time, lead.x, fol.x, fol.y, fol.road))

    engine, _ = run_scenario(write(tmp_path / "j.xosc", text), tmp_path, until=2.5, on_step=on_step)
    assert all(fx == pytest.approx(lx - 30.0, abs=1e-6) for _, lx, fx, _, _ in seen)
    assert all(fy == pytest.approx(-2.25, abs=1e-6) for _, _, _, fy, _ in seen)
    assert {road for *_, road in seen} == {"101", "2"}
    started = {n for _, _, n, tr in engine.tree.log if tr == "startTransition"}
    assert "NearAction" in started and "FarAction" not in started
    assert "RNearAction" in started and "RFarAction" not in started


def test_road_distance_between_unlinked_roads_never_holds(tmp_path: Path) -> None:
    """Two parallel roads with no link between them (road 1 at y = 0, road 2 at y = 30): the
    road-frame distance from one to the other is not measured, so neither rule holds."""
    root = opendrive()
    road(root, 1, (0.0, 0.0, 0.0), 200.0, TOWN)
    road(root, 2, (0.0, 30.0, 0.0), 200.0, TOWN)
    xodr = write_xodr(root, tmp_path / "apart.xodr")
    init = _place("Ego", 1, 10, 0) + _place("Lead", 2, 50, 10) + _place("Follow", 1, 50, 10)
    stories = "".join(
        story("Ego", NOOP, _lane_distance(name, 1000.0, rule, "road"), name)
        for name, rule in (("Below", "lessThan"), ("Above", "greaterThan"))
    )
    text = scenario_xml({"Ego": "", "Lead": "", "Follow": ""}, init, stories,
                        f"<ConditionGroup>{time_condition(0.5, 'end')}</ConditionGroup>",
                        road=xodr)  # fmt: skip
    engine, report = run_scenario(write(tmp_path / "u.xosc", text), tmp_path, until=1.0)
    started = {n for _, _, n, tr in engine.tree.log if tr == "startTransition"}
    assert report.finished and not {"BelowAction", "AboveAction"} & started
