"""OpenSCENARIO <PrivateAction> -> model actions."""

from __future__ import annotations

from lxml import etree

from hiyari.bridge.openscenario.model.actions import (
    AbsoluteLane,
    AbsoluteOffset,
    AbsoluteSpeed,
    AcquirePositionAction,
    ActionBody,
    ActivateControllerAction,
    AssignControllerAction,
    AssignRouteAction,
    Dimension,
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LateralDistanceAction,
    LightStateAction,
    LongitudinalDistanceAction,
    RandomRouteAction,
    RelativeLane,
    RelativeOffset,
    RelativeSpeed,
    Shape,
    SpeedAction,
    SpeedProfileAction,
    SynchronizeAction,
    TeleportAction,
    Timing,
    TransitionDynamics,
    VisibilityAction,
)
from hiyari.bridge.openscenario.model.entities import ControllerSpec
from hiyari.bridge.openscenario.xosc.context import Ctx
from hiyari.bridge.openscenario.xosc.elements.read_positions import read_position
from hiyari.bridge.openscenario.xosc.elements.read_trajectories import read_route, read_trajectory


def read_private_action(ctx: Ctx, el: etree._Element) -> ActionBody:
    """The body of one <PrivateAction>."""
    kind = ctx.one(el)
    if kind.tag == "TeleportAction":
        return TeleportAction(read_position(ctx, ctx.child(kind, "Position")))
    if kind.tag == "SynchronizeAction":
        return _synchronize(ctx, kind)
    if kind.tag == "VisibilityAction":
        if kind.find("SensorReferenceSet") is not None:
            raise ctx.unsupported(
                kind.find("SensorReferenceSet"),
                "hiyari's sensors see an entity all or none (no sensor by reference)",
            )
        if not ctx.flag(kind, "traffic"):
            raise ctx.unsupported(
                kind, "traffic = false: SUMO's own traffic always sees the vehicles on its lanes"
            )
        return VisibilityAction(
            ctx.flag(kind, "graphics"), ctx.flag(kind, "traffic"), ctx.flag(kind, "sensors")
        )
    if kind.tag == "AppearanceAction":
        what = ctx.one(kind)
        if what.tag == "AnimationAction":
            raise ctx.unsupported(what, "hiyari's actors are rigid boxes with no animated parts")
        light = ctx.one(ctx.child(what, "LightType"))
        state = ctx.child(what, "LightState")
        user = light.tag == "UserDefinedLight"
        name = ctx.text(light, "userDefinedLightType" if user else "vehicleLightType")
        return LightStateAction(name, ctx.text(state, "mode"), user)
    if kind.tag == "ActivateControllerAction":  # 1.0 placement, deprecated
        return _activate(ctx, kind)
    group = {
        "LongitudinalAction": _LONGITUDINAL,
        "LateralAction": _LATERAL,
        "ControllerAction": _CONTROLLER,
        "RoutingAction": _ROUTING,
    }.get(kind.tag)
    if group is None:
        raise ctx.unsupported(kind)
    action = ctx.one(kind)
    reader = group.get(action.tag)
    if reader is None:
        raise ctx.unsupported(action)
    return reader(ctx, action)


def read_dynamics(ctx: Ctx, el: etree._Element) -> TransitionDynamics:
    """A TransitionDynamics element (SpeedActionDynamics, LaneChangeActionDynamics, ...)."""
    if el.get("followingMode") == "follow":
        raise ctx.unsupported(el, "followingMode follow")
    return TransitionDynamics(
        Shape(ctx.text(el, "dynamicsShape")),
        Dimension(ctx.text(el, "dynamicsDimension")),
        ctx.num(el, "value"),
    )


def _speed(ctx: Ctx, el: etree._Element) -> ActionBody:
    target = ctx.one(ctx.child(el, "SpeedActionTarget"))
    if target.tag == "AbsoluteTargetSpeed":
        tgt: AbsoluteSpeed | RelativeSpeed = AbsoluteSpeed(ctx.num(target, "value"))
    else:
        tgt = RelativeSpeed(
            ctx.text(target, "entityRef"),
            ctx.num(target, "value"),
            ctx.text(target, "speedTargetValueType", "delta"),
            ctx.flag(target, "continuous", False),
        )
    return SpeedAction(read_dynamics(ctx, ctx.child(el, "SpeedActionDynamics")), tgt)


def _synchronize(ctx: Ctx, el: etree._Element) -> ActionBody:
    final = el.find("FinalSpeed")
    speed, relative, steady_d, steady_t = None, "", None, None
    if final is not None:
        f = ctx.one(final)
        speed = ctx.num(f, "value")
        if f.tag == "RelativeSpeedToMaster":
            relative = ctx.text(f, "speedTargetValueType")
        d, t = f.find("TargetDistanceSteadyState"), f.find("TargetTimeSteadyState")
        steady_d = None if d is None else ctx.num(d, "distance")
        steady_t = None if t is None else ctx.num(t, "time")
    return SynchronizeAction(
        ctx.text(el, "masterEntityRef"),
        read_position(ctx, ctx.child(el, "TargetPositionMaster")),
        read_position(ctx, ctx.child(el, "TargetPosition")),
        speed,
        relative,
        steady_d,
        steady_t,
        ctx.num(el, "targetToleranceMaster", 0.0),
        ctx.num(el, "targetTolerance", 0.0),
    )


def _limits(ctx: Ctx, dyn: etree._Element) -> tuple[float | None, float | None, float | None]:
    """A DynamicConstraints' (maxAcceleration, maxDeceleration, maxSpeed), None where absent."""
    return tuple(ctx.opt_num(dyn, k) for k in ("maxAcceleration", "maxDeceleration", "maxSpeed"))


def _long_distance(ctx: Ctx, el: etree._Element) -> ActionBody:
    dyn = el.find("DynamicConstraints")
    limits = None if dyn is None else _limits(ctx, dyn)
    system = ctx.text(el, "coordinateSystem", "entity")
    if system not in ("entity", "road", "lane"):
        raise ctx.unsupported(el, f"coordinateSystem {el.get('coordinateSystem')}")
    return LongitudinalDistanceAction(
        ctx.text(el, "entityRef"),
        ctx.opt_num(el, "distance"),
        ctx.opt_num(el, "timeGap"),
        ctx.flag(el, "freespace"),
        ctx.flag(el, "continuous"),
        ctx.text(el, "displacement", "trailingReferencedEntity"),
        limits,
        system,
    )


def _lane_change(ctx: Ctx, el: etree._Element) -> ActionBody:
    target = ctx.one(ctx.child(el, "LaneChangeTarget"))
    if target.tag == "RelativeTargetLane":
        tgt: AbsoluteLane | RelativeLane = RelativeLane(
            ctx.text(target, "entityRef"), ctx.int(target, "value")
        )
    else:
        tgt = AbsoluteLane(ctx.int(target, "value"))
    return LaneChangeAction(
        read_dynamics(ctx, ctx.child(el, "LaneChangeActionDynamics")),
        tgt,
        ctx.num(el, "targetLaneOffset", 0.0),
    )


def _lane_offset(ctx: Ctx, el: etree._Element) -> ActionBody:
    dyn = ctx.child(el, "LaneOffsetActionDynamics")
    shape = Shape(ctx.text(dyn, "dynamicsShape"))
    max_acc = ctx.opt_num(dyn, "maxLateralAcc")
    if shape != Shape.STEP and (max_acc is None or max_acc <= 0):
        raise ctx.unsupported(dyn, f"a {shape} lane offset needs a positive maxLateralAcc")
    if shape == Shape.LINEAR:
        raise ctx.unsupported(
            dyn, "a linear lateral ramp has no finite peak acceleration; use cubic or sinusoidal"
        )
    target = ctx.one(ctx.child(el, "LaneOffsetTarget"))
    if target.tag == "RelativeTargetLaneOffset":
        tgt: AbsoluteOffset | RelativeOffset = RelativeOffset(
            ctx.text(target, "entityRef"), ctx.num(target, "value")
        )
    else:
        tgt = AbsoluteOffset(ctx.num(target, "value"))
    return LaneOffsetAction(tgt, shape, max_acc or 0.0, ctx.flag(el, "continuous"))


def read_controller(ctx: Ctx, el: etree._Element) -> ControllerSpec:
    """A <Controller> or a CatalogReference to one."""
    if el.tag == "CatalogReference":
        el, ctx = ctx.catalogs.resolve(ctx, el)
    if el.tag != "Controller":
        raise ctx.unsupported(el)
    ctx = ctx.enter(el)
    props = {}
    pr = el.find("Properties")
    for p in [] if pr is None else pr.findall("Property"):
        props[ctx.text(p, "name")] = ctx.text(p, "value")
    return ControllerSpec(ctx.text(el, "name"), props)


def _assign_controller(ctx: Ctx, el: etree._Element) -> ActionBody:
    src = el.find("Controller")
    if src is None:
        src = el.find("CatalogReference")
    if src is None and el.find("ObjectController") is not None:
        src = ctx.one(el.find("ObjectController"))
    if src is None:
        raise ctx.unsupported(el, "no Controller or CatalogReference")
    return AssignControllerAction(
        read_controller(ctx, src),
        ctx.opt_flag(el, "activateLateral"),
        ctx.opt_flag(el, "activateLongitudinal"),
    )


def _activate(ctx: Ctx, el: etree._Element) -> ActionBody:
    return ActivateControllerAction(
        ctx.opt_flag(el, "lateral"),
        ctx.opt_flag(el, "longitudinal"),
        ctx.opt(el, "objectControllerRef") or ctx.opt(el, "controllerRef"),
    )


def _follow_trajectory(ctx: Ctx, el: etree._Element) -> ActionBody:
    ref = el.find("TrajectoryRef")
    if ref is not None:
        src = ctx.one(ref)
    else:  # 1.0 placement, deprecated
        src = el.find("Trajectory")
        if src is None:
            src = ctx.child(el, "CatalogReference")
    timing = None
    tref = el.find("TimeReference")
    if tref is not None and tref.find("Timing") is not None:
        t = tref.find("Timing")
        timing = Timing(
            ctx.text(t, "domainAbsoluteRelative") == "absolute",
            ctx.num(t, "scale"),
            ctx.num(t, "offset"),
        )
    mode = el.find("TrajectoryFollowingMode")
    following = "position" if mode is None else ctx.text(mode, "followingMode")
    return FollowTrajectoryAction(
        read_trajectory(ctx, src), timing, following, ctx.num(el, "initialDistanceOffset", 0.0)
    )


def _assign_route(ctx: Ctx, el: etree._Element) -> ActionBody:
    route = read_route(ctx, ctx.one(el))
    return AssignRouteAction(route.name, route.waypoints, route.closed)


def _speed_profile(ctx: Ctx, el: etree._Element) -> ActionBody:
    dyn = el.find("DynamicConstraints")
    limit = (lambda k: None) if dyn is None else (lambda k: ctx.opt_num(dyn, k))
    entries = tuple(
        (ctx.num(e, "speed"), ctx.opt_num(e, "time")) for e in el.findall("SpeedProfileEntry")
    )
    return SpeedProfileAction(
        entries,
        ctx.text(el, "followingMode"),
        ctx.opt(el, "entityRef"),
        limit("maxAcceleration"),
        limit("maxDeceleration"),
        limit("maxSpeed"),
        limit("maxAccelerationRate"),
        limit("maxDecelerationRate"),
    )


_LONGITUDINAL = {
    "SpeedAction": _speed,
    "LongitudinalDistanceAction": _long_distance,
    "SpeedProfileAction": _speed_profile,
}


def _lateral_distance(ctx: Ctx, el: etree._Element) -> ActionBody:
    if ctx.text(el, "coordinateSystem", "entity") not in ("entity", "road", "lane"):
        raise ctx.unsupported(el, f"coordinateSystem {el.get('coordinateSystem')}")
    dyn = el.find("DynamicConstraints")
    return LateralDistanceAction(
        ctx.text(el, "entityRef"),
        ctx.num(el, "distance", 0.0),
        ctx.flag(el, "freespace"),
        ctx.flag(el, "continuous"),
        ctx.text(el, "displacement", "any"),
        None if dyn is None else _limits(ctx, dyn),
    )


_LATERAL = {
    "LaneChangeAction": _lane_change,
    "LaneOffsetAction": _lane_offset,
    "LateralDistanceAction": _lateral_distance,
}
_CONTROLLER = {
    "AssignControllerAction": _assign_controller,
    "ActivateControllerAction": _activate,
}
_ROUTING = {
    "AssignRouteAction": _assign_route,
    "FollowTrajectoryAction": _follow_trajectory,
    "AcquirePositionAction": lambda ctx, el: AcquirePositionAction(
        read_position(ctx, ctx.child(el, "Position"))
    ),
    "RandomRouteAction": lambda ctx, el: RandomRouteAction(),
}
