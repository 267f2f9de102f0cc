"""Export a concrete catalogue case as ASAM OpenSCENARIO 1.2 XML next to its OpenDRIVE road,
so esmini / CARLA users can run the same case. Written with lxml from the case's scenario
model; the file validates against the OpenSCENARIO XSD (hiyari's reader checks it).

The ego's own lane change becomes a LaneChangeAction event on the ego (a stack-driven ego in
hiyari ignores it; hiyari commands it instead, see the runner).
"""

from __future__ import annotations

import shutil
from pathlib import Path

from lxml import etree

from hiyari.atomic import write_text_atomic
from hiyari.bridge.openscenario.model import (
    AbsoluteLane,
    Action,
    Dimension,
    Entity,
    LaneChangeAction,
    LanePosition,
    Shape,
    SpeedAction,
    TeleportAction,
    TransitionDynamics,
)
from hiyari.bridge.studies.catalogue.evaluation.runner import prepare_road
from hiyari.bridge.studies.catalogue.space.concrete import ConcreteCase, to_scenario
from hiyari.errors import HiyariError

E = etree.SubElement


def _vehicle(parent: etree._Element, e: Entity) -> None:
    obj = E(parent, "ScenarioObject", name=e.name)
    v = E(obj, "Vehicle", name=f"{e.name}_car", vehicleCategory="car")
    box = E(v, "BoundingBox")
    E(box, "Center", x="0", y="0", z=repr(e.height / 2))
    E(box, "Dimensions", width=repr(e.width), length=repr(e.length), height=repr(e.height))
    E(v, "Performance", maxSpeed="70", maxAcceleration="10", maxDeceleration="10")
    axles = E(v, "Axles")
    for tag, x in (("FrontAxle", 0.3 * e.length), ("RearAxle", -0.3 * e.length)):
        E(axles, tag, maxSteering="0.5", wheelDiameter="0.6", trackWidth="1.6",
          positionX=repr(x), positionZ="0.3")  # fmt: skip
    E(v, "Properties")


def _private_action(parent: etree._Element, action: Action) -> None:
    pa = E(parent, "PrivateAction")
    body = action.body
    if isinstance(body, TeleportAction):
        p = body.position
        if not isinstance(p, LanePosition):
            raise HiyariError(f"{action.name}: only lane positions are exported")
        pos = E(E(pa, "TeleportAction"), "Position")
        E(
            pos,
            "LanePosition",
            roadId=p.road,
            laneId=str(p.lane),
            s=repr(p.s),
            offset=repr(p.offset),
        )
    elif isinstance(body, SpeedAction):
        sa = E(E(pa, "LongitudinalAction"), "SpeedAction")
        d = body.dynamics
        E(sa, "SpeedActionDynamics", dynamicsShape=d.shape.value, value=repr(d.value),
          dynamicsDimension=d.dimension.value)  # fmt: skip
        E(E(sa, "SpeedActionTarget"), "AbsoluteTargetSpeed", value=repr(body.target.value))
    elif isinstance(body, LaneChangeAction):
        la = E(E(pa, "LateralAction"), "LaneChangeAction")
        d = body.dynamics
        E(la, "LaneChangeActionDynamics", dynamicsShape=d.shape.value, value=repr(d.value),
          dynamicsDimension=d.dimension.value)  # fmt: skip
        E(E(la, "LaneChangeTarget"), "AbsoluteTargetLane", value=str(body.target.lane))


def _time_trigger(parent: etree._Element, tag: str, name: str, t: float, edge: str) -> None:
    cond = E(E(E(parent, tag), "ConditionGroup"), "Condition", name=name, delay="0",
             conditionEdge=edge)  # fmt: skip
    E(E(cond, "ByValueCondition"), "SimulationTimeCondition", value=repr(t), rule="greaterThan")


def _event(maneuver: etree._Element, name: str, action: Action, t: float) -> None:
    ev = E(maneuver, "Event", name=name, priority="overwrite", maximumExecutionCount="1")
    _private_action(E(ev, "Action", name=action.name), action)
    _time_trigger(ev, "StartTrigger", f"{name}_time", t, "rising")


def case_xosc(case: ConcreteCase, xodr_name: str) -> str:
    """The OpenSCENARIO XML of ``case`` on the road file ``xodr_name`` (relative path)."""
    sc = to_scenario(case)
    root = etree.Element("OpenSCENARIO")
    E(root, "FileHeader", revMajor="1", revMinor="2", date="2026-01-01T00:00:00",
      description=f"hiyari JAMA catalogue case {case.run_id}: {case.cell.combination.title}, "
                  f"{case.cell.position.value}, {case.cell.lanes} lanes", author="hiyari")  # fmt: skip
    E(root, "ParameterDeclarations")
    E(root, "CatalogLocations")
    E(E(root, "RoadNetwork"), "LogicFile", filepath=xodr_name)
    ents = E(root, "Entities")
    for e in sc.entities:
        _vehicle(ents, e)
    board = E(root, "Storyboard")
    actions = E(E(board, "Init"), "Actions")
    for name in [e.name for e in sc.entities]:
        priv = E(actions, "Private", entityRef=name)
        for ia in sc.storyboard.init:
            if ia.entity == name:
                _private_action(priv, ia.action)
    story = E(board, "Story", name="disturbance")
    act = E(story, "Act", name="act")
    for actor, events in _events(case, sc):
        group = E(act, "ManeuverGroup", maximumExecutionCount="1", name=f"{actor}_group")
        E(E(group, "Actors", selectTriggeringEntities="false"), "EntityRef", entityRef=actor)
        maneuver = E(group, "Maneuver", name=f"{actor}_maneuver")
        for name, action, t in events:
            _event(maneuver, name, action, t)
    _time_trigger(act, "StartTrigger", "start", 0.0, "none")
    _time_trigger(board, "StopTrigger", "end", case.ranges.duration, "rising")
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8").decode()


def _events(case: ConcreteCase, sc: object) -> list[tuple[str, list]]:
    out = []
    for story in sc.storyboard.stories:
        for act in story.acts:
            for group in act.groups:
                for m in group.maneuvers:
                    evs = [(ev.name, ev.actions[0], case.ranges.event_time) for ev in m.events]
                    out.append((group.actors[0], evs))
    lc = case.ego_lane_change()
    if lc is not None:
        dyn = TransitionDynamics(Shape.LINEAR, Dimension.RATE, lc.lateral_speed)
        act = Action("ego_lane_change", LaneChangeAction(dyn, AbsoluteLane(lc.lane)))
        out.append(("ego", [("ego_lane_change", act, lc.time)]))
    return [o for o in out if o[1]]


def export_case(case: ConcreteCase, roads: Path, folder: Path) -> Path:
    """Write ``folder/<run_id>.xosc`` and its road ``folder/<road>.xodr``; return the .xosc."""
    xodr, _ = prepare_road(roads, case.cell.combination.geometry.value, case.cell.lanes)
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / xodr.name
    if not target.is_file():
        shutil.copyfile(xodr, target)
    out = folder / f"{case.run_id}.xosc"
    write_text_atomic(out, case_xosc(case, xodr.name))
    return out
