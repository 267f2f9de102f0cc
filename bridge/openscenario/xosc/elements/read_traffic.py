"""OpenSCENARIO <TrafficAction> (source, sink, swarm, stop) -> model traffic actions."""

from __future__ import annotations

from lxml import etree

from hiyari.bridge.openscenario.model.global_actions import (
    GlobalActionBody,
    TrafficAreaAction,
    TrafficMix,
    TrafficSinkAction,
    TrafficSourceAction,
    TrafficStopAction,
    TrafficSwarmAction,
)
from hiyari.bridge.openscenario.xosc.context import Ctx
from hiyari.bridge.openscenario.xosc.elements.read_positions import read_position
from hiyari.errors import HiyariError


def read_traffic(ctx: Ctx, el: etree._Element) -> GlobalActionBody:
    """The body of a <TrafficAction>."""
    name = ctx.text(el, "trafficName", "")
    kind = ctx.one(el)
    if kind.tag == "TrafficStopAction":
        return TrafficStopAction(name)
    if kind.tag == "TrafficSinkAction":
        return TrafficSinkAction(
            name,
            read_position(ctx, ctx.child(kind, "Position")),
            ctx.num(kind, "radius"),
            ctx.opt_num(kind, "rate"),
        )
    if kind.tag == "TrafficSourceAction":
        speed = ctx.opt_num(kind, "speed")
        return TrafficSourceAction(
            name,
            read_position(ctx, ctx.child(kind, "Position")),
            ctx.num(kind, "radius"),
            ctx.num(kind, "rate"),
            speed if speed is not None else ctx.opt_num(kind, "velocity"),
            _mix(ctx, kind),
        )
    if kind.tag == "TrafficSwarmAction":
        rng, dot = kind.find("InitialSpeedRange"), kind.find("DirectionOfTravelDistribution")
        return TrafficSwarmAction(
            name,
            ctx.text(ctx.child(kind, "CentralObject"), "entityRef"),
            ctx.num(kind, "innerRadius"),
            ctx.num(kind, "semiMajorAxis"),
            ctx.num(kind, "semiMinorAxis"),
            ctx.num(kind, "offset"),
            ctx.int(kind, "numberOfVehicles"),
            None if rng is None else (ctx.num(rng, "lowerLimit"), ctx.num(rng, "upperLimit")),
            1.0 if dot is None else ctx.num(dot, "same"),
            0.0 if dot is None else ctx.num(dot, "opposite"),
            _mix(ctx, kind),
        )
    if kind.tag == "TrafficAreaAction":
        area = ctx.one(ctx.child(kind, "TrafficArea"))
        polygon, ranges = (), []
        if area.tag == "Polygon":
            polygon = tuple(read_position(ctx, p) for p in area.findall("Position"))
        else:
            for rr in ctx.child(kind, "TrafficArea").findall("RoadRange"):
                cursors = rr.findall("RoadCursor")
                for a, b in zip(cursors[:-1], cursors[1:], strict=True):
                    road = ctx.text(a, "roadId")
                    if ctx.text(b, "roadId") != road:
                        raise HiyariError(
                            f"{ctx.where(b)}: a road range runs along one road here "
                            f"(from road {road} to road {ctx.text(b, 'roadId')})"
                        )
                    lanes = tuple(ctx.int(ln, "id") for ln in a.findall("Lane"))
                    ranges.append((road, ctx.num(a, "s", 0.0), ctx.num(b, "s", 1e9), lanes))
        return TrafficAreaAction(
            name, ctx.int(kind, "numberOfEntities"), ctx.flag(kind, "continuous"), polygon,
            tuple(ranges), _mix(ctx, kind),
        )  # fmt: skip
    raise ctx.unsupported(kind)


def _mix(ctx: Ctx, el: etree._Element) -> TrafficMix:
    """TrafficDistribution (1.3) or the deprecated TrafficDefinition's categories; cars when
    neither is given."""
    dist, definition = el.find("TrafficDistribution"), el.find("TrafficDefinition")
    entries: list[tuple[float, str, float | None, float | None, float | None]] = []
    if dist is not None:
        for entry in dist.findall("TrafficDistributionEntry"):
            w = ctx.num(entry, "weight")
            for e in ctx.child(entry, "EntityDistribution").findall("EntityDistributionEntry"):
                body = ctx.one(ctx.child(e, "ScenarioObjectTemplate"))
                bctx = ctx
                if body.tag == "CatalogReference":
                    body, bctx = ctx.catalogs.resolve(ctx, body)
                entries.append((w * ctx.num(e, "weight"), *_template(bctx.enter(body), body)))
    elif definition is not None:
        cats = ctx.child(definition, "VehicleCategoryDistribution")
        for e in cats.findall("VehicleCategoryDistributionEntry"):
            entries.append((ctx.num(e, "weight"), ctx.text(e, "category"), None, None, None))
    return TrafficMix(tuple(entries) or ((1.0, "car", None, None, None),))


def _template(ctx: Ctx, body: etree._Element) -> tuple[str, float, float, float]:
    if body.tag == "Vehicle":
        cat = ctx.text(body, "vehicleCategory")
    elif body.tag == "Pedestrian":
        cat = "pedestrian"
    else:
        raise ctx.unsupported(body, "traffic is made of vehicles and pedestrians")
    dim = ctx.child(ctx.child(body, "BoundingBox"), "Dimensions")
    return cat, ctx.num(dim, "length"), ctx.num(dim, "width"), ctx.num(dim, "height")
