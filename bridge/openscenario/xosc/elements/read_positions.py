"""OpenSCENARIO <Position> -> model positions."""

from __future__ import annotations

import math

from lxml import etree

from hiyari.bridge.openscenario.model.positions import (
    GeoPosition,
    LanePosition,
    Orientation,
    Position,
    RelativeLanePosition,
    RelativeObjectPosition,
    RelativeRoadPosition,
    RelativeWorldPosition,
    RoadPosition,
    RoutePosition,
    TrajectoryPosition,
    WorldPosition,
)
from hiyari.bridge.openscenario.xosc.context import Ctx


def read_position(ctx: Ctx, el: etree._Element) -> Position:
    """A <Position> element (its single child) as a model position."""
    p = ctx.one(el)
    reader = _READERS.get(p.tag)
    if reader is None:
        raise ctx.unsupported(p)
    return reader(ctx, p)


def _orientation(ctx: Ctx, el: etree._Element) -> Orientation | None:
    o = el.find("Orientation")
    if o is None:
        return None
    if ctx.num(o, "p", 0.0) != 0.0 or ctx.num(o, "r", 0.0) != 0.0:
        raise ctx.unsupported(o, "pitch and roll are not modelled")
    return Orientation(ctx.num(o, "h", 0.0), ctx.text(o, "type", "relative") == "relative")


def _world(ctx: Ctx, p: etree._Element) -> Position:
    return WorldPosition(
        ctx.num(p, "x"), ctx.num(p, "y"), ctx.num(p, "z", 0.0), ctx.num(p, "h", 0.0)
    )


def _lane(ctx: Ctx, p: etree._Element) -> Position:
    return LanePosition(
        ctx.text(p, "roadId"),
        ctx.int(p, "laneId"),
        ctx.num(p, "s"),
        ctx.num(p, "offset", 0.0),
        _orientation(ctx, p),
    )


def _road(ctx: Ctx, p: etree._Element) -> Position:
    return RoadPosition(
        ctx.text(p, "roadId"), ctx.num(p, "s"), ctx.num(p, "t"), _orientation(ctx, p)
    )


def _rel_lane(ctx: Ctx, p: etree._Element) -> Position:
    ds, ds_lane = ctx.opt_num(p, "ds"), ctx.opt_num(p, "dsLane")
    return RelativeLanePosition(
        ctx.text(p, "entityRef"),
        ctx.int(p, "dLane"),
        ds if ds is not None else (ds_lane or 0.0),
        ctx.num(p, "offset", 0.0),
        ds is None and ds_lane is not None,
        _orientation(ctx, p),
    )


def _rel_road(ctx: Ctx, p: etree._Element) -> Position:
    return RelativeRoadPosition(
        ctx.text(p, "entityRef"), ctx.num(p, "ds"), ctx.num(p, "dt"), _orientation(ctx, p)
    )


def _rel_object(ctx: Ctx, p: etree._Element) -> Position:
    return RelativeObjectPosition(
        ctx.text(p, "entityRef"),
        ctx.num(p, "dx"),
        ctx.num(p, "dy"),
        ctx.num(p, "dz", 0.0),
        _orientation(ctx, p),
    )


def _rel_world(ctx: Ctx, p: etree._Element) -> Position:
    return RelativeWorldPosition(
        ctx.text(p, "entityRef"),
        ctx.num(p, "dx"),
        ctx.num(p, "dy"),
        ctx.num(p, "dz", 0.0),
        _orientation(ctx, p),
    )


def _trajectory(ctx: Ctx, p: etree._Element) -> Position:
    from hiyari.bridge.openscenario.xosc.elements.read_trajectories import read_trajectory_ref

    return TrajectoryPosition(
        read_trajectory_ref(ctx, ctx.child(p, "TrajectoryRef")),
        ctx.num(p, "s"),
        ctx.num(p, "t", 0.0),
        _orientation(ctx, p),
    )


def _route(ctx: Ctx, p: etree._Element) -> Position:
    from hiyari.bridge.openscenario.xosc.elements.read_trajectories import read_route

    route = read_route(ctx, ctx.one(ctx.child(p, "RouteRef")))
    where = ctx.one(ctx.child(p, "InRoutePosition"))
    o = _orientation(ctx, p)
    if where.tag == "FromCurrentEntity":
        return RoutePosition(route, entity=ctx.text(where, "entityRef"), orientation=o)
    if where.tag == "FromRoadCoordinates":
        return RoutePosition(route, ctx.num(where, "pathS"), ctx.num(where, "t"), orientation=o)
    return RoutePosition(
        route,
        ctx.num(where, "pathS"),
        lane=ctx.int(where, "laneId"),
        lane_offset=ctx.num(where, "laneOffset", 0.0),
        orientation=o,
    )


def _geo(ctx: Ctx, p: etree._Element) -> Position:
    lat, lon = ctx.opt_num(p, "latitudeDeg"), ctx.opt_num(p, "longitudeDeg")
    if lat is not None and lon is not None:
        lat, lon = math.radians(lat), math.radians(lon)
    else:  # the deprecated attributes, in radians
        lat, lon = ctx.num(p, "latitude"), ctx.num(p, "longitude")
    alt = ctx.opt_num(p, "altitude")
    return GeoPosition(
        lat, lon, alt if alt is not None else ctx.num(p, "height", 0.0), _orientation(ctx, p)
    )


_READERS = {
    "WorldPosition": _world,
    "LanePosition": _lane,
    "RoadPosition": _road,
    "RelativeLanePosition": _rel_lane,
    "RelativeRoadPosition": _rel_road,
    "RelativeObjectPosition": _rel_object,
    "RelativeWorldPosition": _rel_world,
    "TrajectoryPosition": _trajectory,
    "RoutePosition": _route,
    "GeoPosition": _geo,
}
