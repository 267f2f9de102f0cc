"""OpenSCENARIO <GlobalAction> -> model global actions, and <VariableDeclarations>."""

from __future__ import annotations

from lxml import etree

from hiyari.bridge.openscenario.model.global_actions import (
    AddEntityAction,
    DeleteEntityAction,
    Environment,
    EnvironmentAction,
    Fog,
    GlobalActionBody,
    ParameterModifyAction,
    ParameterSetAction,
    Precipitation,
    RoadCondition,
    SetMonitorAction,
    Sun,
    TrafficSignalControllerAction,
    TrafficSignalStateAction,
    VariableModifyAction,
    VariableSetAction,
    Weather,
    Wind,
)
from hiyari.bridge.openscenario.xosc.context import Ctx, canonical
from hiyari.bridge.openscenario.xosc.elements.read_positions import read_position
from hiyari.bridge.openscenario.xosc.elements.read_traffic import read_traffic
from hiyari.errors import HiyariError

#: The file's modify rules and the model's operations.
_OPS = {"AddValue": "add", "MultiplyByValue": "multiply"}


def read_variables(ctx: Ctx, el: etree._Element | None) -> dict[str, tuple[str, str]]:
    """<VariableDeclarations>: name -> (type, initial value as canonical text)."""
    out: dict[str, tuple[str, str]] = {}
    for d in [] if el is None else el.findall("VariableDeclaration"):
        name, vtype = ctx.text(d, "name"), ctx.text(d, "variableType")
        if name in out:
            raise HiyariError(f"{ctx.where(d)}: variable {name!r} is declared twice")
        out[name] = (vtype, canonical(ctx.text(d, "value"), vtype, ctx.where(d), name))
    return out


def read_monitors(ctx: Ctx, el: etree._Element | None) -> dict[str, bool]:
    """<MonitorDeclarations>: name -> initial value."""
    out: dict[str, bool] = {}
    for d in [] if el is None else el.findall("MonitorDeclaration"):
        name = ctx.text(d, "name")
        if name in out:
            raise HiyariError(f"{ctx.where(d)}: monitor {name!r} is declared twice")
        out[name] = ctx.flag(d, "value")
    return out


def read_global_action(ctx: Ctx, el: etree._Element) -> GlobalActionBody:
    """The body of one <GlobalAction>."""
    kind = ctx.one(el)
    if kind.tag == "VariableAction":
        return _value_action(ctx, kind, "variableRef", VariableSetAction, VariableModifyAction)
    if kind.tag == "ParameterAction":
        return _value_action(ctx, kind, "parameterRef", ParameterSetAction, ParameterModifyAction)
    if kind.tag == "EnvironmentAction":
        src = ctx.one(kind)
        if src.tag == "CatalogReference":
            src, ectx = ctx.catalogs.resolve(ctx, src)
        else:
            ectx = ctx
        return EnvironmentAction(read_environment(ectx.enter(src), src))
    if kind.tag == "InfrastructureAction":
        sig = ctx.one(ctx.child(kind, "TrafficSignalAction"))
        if sig.tag == "TrafficSignalStateAction":
            return TrafficSignalStateAction(ctx.text(sig, "name"), ctx.text(sig, "state"))
        return TrafficSignalControllerAction(
            ctx.text(sig, "trafficSignalControllerRef"), ctx.text(sig, "phase")
        )
    if kind.tag == "TrafficAction":
        return read_traffic(ctx, kind)
    if kind.tag == "SetMonitorAction":
        return SetMonitorAction(ctx.text(kind, "monitorRef"), ctx.flag(kind, "value"))
    if kind.tag == "EntityAction":
        who, what = ctx.text(kind, "entityRef"), ctx.one(kind)
        if what.tag == "DeleteEntityAction":
            return DeleteEntityAction(who)
        return AddEntityAction(who, read_position(ctx, ctx.child(what, "Position")))
    raise ctx.unsupported(kind)


def _value_action(ctx: Ctx, el: etree._Element, ref: str, set_cls: type, mod_cls: type):
    name, what = ctx.text(el, ref), ctx.one(el)
    if what.tag == "SetAction":
        return set_cls(name, ctx.text(what, "value"))
    rule = ctx.one(ctx.child(what, "Rule"))
    return mod_cls(name, _OPS[rule.tag], ctx.num(rule, "value"))


def read_environment(ctx: Ctx, el: etree._Element) -> Environment:
    """An <Environment> element."""
    tod, weather, road = el.find("TimeOfDay"), el.find("Weather"), el.find("RoadCondition")
    return Environment(
        ctx.text(el, "name"),
        None if tod is None else ctx.text(tod, "dateTime"),
        False if tod is None else ctx.flag(tod, "animation"),
        None if weather is None else _weather(ctx, weather),
        None
        if road is None
        else RoadCondition(ctx.num(road, "frictionScaleFactor"), ctx.text(road, "wetness", "")),
    )


def _weather(ctx: Ctx, el: etree._Element) -> Weather:
    sun, fog = el.find("Sun"), el.find("Fog")
    rain, wind = el.find("Precipitation"), el.find("Wind")
    if el.find("DomeImage") is not None:
        raise ctx.unsupported(el.find("DomeImage"), "hiyari renders no sky dome")
    illuminance = None if sun is None else ctx.opt_num(sun, "illuminance")
    if sun is not None and illuminance is None:
        illuminance = ctx.opt_num(sun, "intensity")  # deprecated name of the same value
    intensity = None if rain is None else ctx.opt_num(rain, "precipitationIntensity")
    if rain is not None and intensity is None:
        intensity = ctx.opt_num(rain, "intensity")
    return Weather(
        None
        if sun is None
        else Sun(ctx.num(sun, "azimuth"), ctx.num(sun, "elevation"), illuminance),
        None if fog is None else Fog(ctx.num(fog, "visualRange")),
        None if rain is None else Precipitation(ctx.text(rain, "precipitationType"), intensity),
        None if wind is None else Wind(ctx.num(wind, "direction"), ctx.num(wind, "speed")),
        ctx.opt(el, "fractionalCloudCover") or ctx.opt(el, "cloudState") or "",
        ctx.opt_num(el, "temperature"),
        ctx.opt_num(el, "atmosphericPressure"),
    )
