"""OpenSCENARIO triggers and conditions -> model conditions."""

from __future__ import annotations

from lxml import etree

from hiyari.bridge.openscenario.model.conditions import (
    AccelerationCondition,
    AngleCondition,
    CollisionCondition,
    Condition,
    ConditionBody,
    CoordinateSystem,
    DistanceCondition,
    DistanceType,
    Edge,
    EndOfRoadCondition,
    EntityCondition,
    EntityConditionBody,
    OffroadCondition,
    ParameterCondition,
    ReachPositionCondition,
    RelativeAngleCondition,
    RelativeClearanceCondition,
    RelativeDistanceCondition,
    RelativeSpeedCondition,
    Rule,
    SimulationTimeCondition,
    SpeedCondition,
    StandStillCondition,
    StoryboardElementStateCondition,
    TimeHeadwayCondition,
    TimeOfDayCondition,
    TimeToCollisionCondition,
    TrafficSignalCondition,
    TrafficSignalControllerCondition,
    TraveledDistanceCondition,
    Trigger,
    VariableCondition,
)
from hiyari.bridge.openscenario.xosc.context import Ctx
from hiyari.bridge.openscenario.xosc.elements.read_positions import read_position
from hiyari.errors import HiyariError


def read_trigger(ctx: Ctx, el: etree._Element | None) -> Trigger:
    """A StartTrigger / StopTrigger: OR of condition groups, each an AND of conditions."""
    if el is None:
        return ()
    return tuple(
        tuple(read_condition(ctx, c) for c in g.findall("Condition"))
        for g in el.findall("ConditionGroup")
    )


def read_condition(ctx: Ctx, el: etree._Element) -> Condition:
    """One <Condition>."""
    kind = ctx.one(el)
    body: ConditionBody
    if kind.tag == "ByValueCondition":
        body = _by_value(ctx, ctx.one(kind))
    elif kind.tag == "ByEntityCondition":
        trig = ctx.child(kind, "TriggeringEntities")
        ents = tuple(ctx.text(r, "entityRef") for r in trig.findall("EntityRef"))
        inner = ctx.one(ctx.child(kind, "EntityCondition"))
        body = EntityCondition(
            ents, ctx.text(trig, "triggeringEntitiesRule"), _by_entity(ctx, inner)
        )
    else:
        raise ctx.unsupported(kind)
    return Condition(
        ctx.text(el, "name"),
        body,
        Edge(ctx.text(el, "conditionEdge")),
        ctx.num(el, "delay", 0.0),
        ctx.where(el),
    )


def _rule(ctx: Ctx, el: etree._Element) -> Rule:
    text = ctx.text(el, "rule")
    try:
        return Rule(text)
    except ValueError:
        raise HiyariError(f"{ctx.where(el)}: unknown rule {text!r}") from None


def _by_value(ctx: Ctx, el: etree._Element) -> ConditionBody:
    if el.tag == "SimulationTimeCondition":
        return SimulationTimeCondition(ctx.num(el, "value"), _rule(ctx, el))
    if el.tag == "StoryboardElementStateCondition":
        return StoryboardElementStateCondition(
            ctx.text(el, "storyboardElementType"),
            ctx.text(el, "storyboardElementRef"),
            ctx.text(el, "state"),
        )
    if el.tag == "ParameterCondition":
        return ParameterCondition(
            ctx.text(el, "parameterRef"), ctx.text(el, "value"), _rule(ctx, el)
        )
    if el.tag == "TimeOfDayCondition":
        return TimeOfDayCondition(ctx.text(el, "dateTime"), _rule(ctx, el))
    if el.tag == "TrafficSignalCondition":
        return TrafficSignalCondition(ctx.text(el, "name"), ctx.text(el, "state"))
    if el.tag == "TrafficSignalControllerCondition":
        return TrafficSignalControllerCondition(
            ctx.text(el, "trafficSignalControllerRef"), ctx.text(el, "phase")
        )
    if el.tag == "VariableCondition":
        return VariableCondition(ctx.text(el, "variableRef"), ctx.text(el, "value"), _rule(ctx, el))
    raise ctx.unsupported(el)


def _distance_type(ctx: Ctx, el: etree._Element, default: str) -> DistanceType:
    text = ctx.text(el, "relativeDistanceType", default)
    return DistanceType("euclidianDistance" if text == "cartesianDistance" else text)


def _coordinate_system(ctx: Ctx, el: etree._Element) -> CoordinateSystem:
    """coordinateSystem, or the deprecated alongRoute (true: road)."""
    if el.get("coordinateSystem") is None and el.get("alongRoute") is not None:
        return CoordinateSystem.ROAD if ctx.flag(el, "alongRoute") else CoordinateSystem.ENTITY
    return CoordinateSystem(ctx.text(el, "coordinateSystem", "entity"))


def _relative_distance(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    return RelativeDistanceCondition(
        ctx.text(el, "entityRef"),
        _distance_type(ctx, el, "euclidianDistance"),
        ctx.num(el, "value"),
        ctx.flag(el, "freespace"),
        _rule(ctx, el),
        _coordinate_system(ctx, el),
    )


def _distance(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    return DistanceCondition(
        read_position(ctx, ctx.child(el, "Position")),
        _distance_type(ctx, el, "euclidianDistance"),
        ctx.num(el, "value"),
        ctx.flag(el, "freespace"),
        _rule(ctx, el),
        _coordinate_system(ctx, el),
    )


def _headway(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    return TimeHeadwayCondition(
        ctx.text(el, "entityRef"),
        ctx.num(el, "value"),
        ctx.flag(el, "freespace"),
        _rule(ctx, el),
        _coordinate_system(ctx, el),
        _distance_type(ctx, el, "longitudinal"),
    )


def _ttc(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    target = ctx.one(ctx.child(el, "TimeToCollisionConditionTarget"))
    entity = ctx.text(target, "entityRef") if target.tag == "EntityRef" else None
    position = read_position(ctx, target) if target.tag == "Position" else None
    frame, kind = _coordinate_system(ctx, el), _distance_type(ctx, el, "euclidianDistance")
    if frame == CoordinateSystem.LANE and kind == DistanceType.LATERAL:
        raise ctx.unsupported(el, "a lateral time to collision in lanes (coordinateSystem lane)")
    return TimeToCollisionCondition(
        ctx.num(el, "value"),
        ctx.flag(el, "freespace"),
        _rule(ctx, el),
        entity,
        position,
        frame,
        kind,
    )


_DIRECTIONS = ("longitudinal", "lateral", "vertical")


def _direction(ctx: Ctx, el: etree._Element) -> str | None:
    """A DirectionalDimension attribute ``direction`` (None: not given)."""
    text = ctx.opt(el, "direction")
    if text is not None and text not in _DIRECTIONS:
        raise HiyariError(
            f"{ctx.where(el)}: direction {text!r} is not one of {', '.join(_DIRECTIONS)}"
        )
    return text


def _speed(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    return SpeedCondition(ctx.num(el, "value"), _rule(ctx, el), _direction(ctx, el))


def _accel(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    return AccelerationCondition(ctx.num(el, "value"), _rule(ctx, el), _direction(ctx, el))


def _collision(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    ref, by_type = el.find("EntityRef"), el.find("ByType")
    if ref is not None:
        return CollisionCondition(entity=ctx.text(ref, "entityRef"))
    if by_type is not None:
        return CollisionCondition(by_type=ctx.text(by_type, "type"))
    return CollisionCondition()


def _reach(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    return ReachPositionCondition(
        read_position(ctx, ctx.child(el, "Position")), ctx.num(el, "tolerance")
    )


def _clearance(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    ranges = tuple(
        (ctx.int(r, "from", -1000), ctx.int(r, "to", 1000)) for r in el.findall("RelativeLaneRange")
    )
    return RelativeClearanceCondition(
        ctx.flag(el, "oppositeLanes"),
        ctx.flag(el, "freeSpace"),
        ctx.num(el, "distanceForward", 0.0),
        ctx.num(el, "distanceBackward", 0.0),
        ranges,
        tuple(ctx.text(r, "entityRef") for r in el.findall("EntityRef")),
    )


_ENTITY_READERS = {
    "RelativeDistanceCondition": _relative_distance,
    "DistanceCondition": _distance,
    "TimeHeadwayCondition": _headway,
    "TimeToCollisionCondition": _ttc,
    "SpeedCondition": _speed,
    "AccelerationCondition": _accel,
    "CollisionCondition": _collision,
    "ReachPositionCondition": _reach,
    "RelativeSpeedCondition": lambda ctx, el: RelativeSpeedCondition(
        ctx.text(el, "entityRef"), ctx.num(el, "value"), _rule(ctx, el), _direction(ctx, el)
    ),
    "StandStillCondition": lambda ctx, el: StandStillCondition(ctx.num(el, "duration")),
    "TraveledDistanceCondition": lambda ctx, el: TraveledDistanceCondition(ctx.num(el, "value")),
    "EndOfRoadCondition": lambda ctx, el: EndOfRoadCondition(ctx.num(el, "duration")),
    "OffroadCondition": lambda ctx, el: OffroadCondition(ctx.num(el, "duration")),
    "RelativeClearanceCondition": lambda ctx, el: _clearance(ctx, el),
    "AngleCondition": lambda ctx, el: AngleCondition(
        ctx.text(el, "angleType"),
        ctx.num(el, "angle"),
        ctx.num(el, "angleTolerance"),
        _coordinate_system(ctx, el),
    ),
    "RelativeAngleCondition": lambda ctx, el: RelativeAngleCondition(
        ctx.text(el, "entityRef"),
        ctx.text(el, "angleType"),
        ctx.num(el, "angle"),
        ctx.num(el, "angleTolerance"),
    ),
}


def _by_entity(ctx: Ctx, el: etree._Element) -> EntityConditionBody:
    reader = _ENTITY_READERS.get(el.tag)
    if reader is None:
        raise ctx.unsupported(el)
    return reader(ctx, el)
