"""OpenSCENARIO <Trajectory> (polyline, clothoid, clothoid spline, NURBS) and <Route>, inline
or from a catalog, -> model trajectories and routes."""

from __future__ import annotations

from lxml import etree

from hiyari.bridge.openscenario.model.trajectories import (
    Clothoid,
    ClothoidSpline,
    ClothoidSplineSegment,
    ControlPoint,
    Nurbs,
    Polyline,
    Route,
    Trajectory,
    TrajectoryShape,
    Vertex,
)
from hiyari.bridge.openscenario.xosc.context import Ctx
from hiyari.bridge.openscenario.xosc.elements.read_positions import read_position
from hiyari.errors import HiyariError


def read_trajectory(ctx: Ctx, el: etree._Element) -> Trajectory:
    """A <Trajectory> or a CatalogReference to one."""
    if el.tag == "CatalogReference":
        el, ctx = ctx.catalogs.resolve(ctx, el)
    if el.tag != "Trajectory":
        raise ctx.unsupported(el)
    ctx = ctx.enter(el)
    shape = ctx.one(ctx.child(el, "Shape"))
    reader = _SHAPES.get(shape.tag)
    if reader is None:
        raise ctx.unsupported(shape)
    return Trajectory(ctx.text(el, "name"), reader(ctx, shape), ctx.flag(el, "closed", False))


def read_trajectory_ref(ctx: Ctx, el: etree._Element) -> Trajectory:
    """A <TrajectoryRef>: its Trajectory or CatalogReference."""
    return read_trajectory(ctx, ctx.one(el))


def read_route(ctx: Ctx, el: etree._Element) -> Route:
    """A <Route> or a CatalogReference to one."""
    if el.tag == "CatalogReference":
        el, ctx = ctx.catalogs.resolve(ctx, el)
    if el.tag != "Route":
        raise ctx.unsupported(el)
    ctx = ctx.enter(el)
    waypoints = el.findall("Waypoint")
    if len(waypoints) < 2:
        raise HiyariError(f"{ctx.where(el)}: a route needs at least two waypoints")
    return Route(
        ctx.text(el, "name"),
        tuple(read_position(ctx, ctx.child(w, "Position")) for w in waypoints),
        ctx.flag(el, "closed", False),
    )


def _polyline(ctx: Ctx, el: etree._Element) -> TrajectoryShape:
    vertices = tuple(
        Vertex(ctx.opt_num(v, "time"), read_position(ctx, ctx.child(v, "Position")))
        for v in el.findall("Vertex")
    )
    if len(vertices) < 2:
        raise HiyariError(f"{ctx.where(el)}: a polyline needs at least two vertices")
    return Polyline(vertices)


def _clothoid(ctx: Ctx, el: etree._Element) -> TrajectoryShape:
    length = ctx.num(el, "length")
    if length <= 0:
        raise HiyariError(f"{ctx.where(el)}: clothoid length {length:g} m is not positive")
    prime = ctx.opt_num(el, "curvaturePrime")
    if prime is None:
        prime = ctx.num(el, "curvatureDot", 0.0)  # the deprecated name (a rate per metre)
    return Clothoid(
        read_position(ctx, ctx.child(el, "Position")),
        ctx.num(el, "curvature"),
        length,
        prime,
        ctx.opt_num(el, "startTime"),
        ctx.opt_num(el, "stopTime"),
    )


def _clothoid_spline(ctx: Ctx, el: etree._Element) -> TrajectoryShape:
    segments = []
    for seg in el.findall("ClothoidSplineSegment"):
        length = ctx.num(seg, "length")
        if length <= 0:
            raise HiyariError(f"{ctx.where(seg)}: segment length {length:g} m is not positive")
        start = seg.find("PositionStart")
        segments.append(
            ClothoidSplineSegment(
                ctx.num(seg, "curvatureStart"),
                ctx.num(seg, "curvatureEnd"),
                length,
                ctx.num(seg, "hOffset", 0.0),
                ctx.opt_num(seg, "timeStart"),
                None if start is None else read_position(ctx, start),
            )
        )
    return ClothoidSpline(tuple(segments), ctx.opt_num(el, "timeEnd"))


def _nurbs(ctx: Ctx, el: etree._Element) -> TrajectoryShape:
    order = ctx.int(el, "order")
    points = tuple(
        ControlPoint(
            read_position(ctx, ctx.child(p, "Position")),
            ctx.opt_num(p, "time"),
            ctx.num(p, "weight", 1.0),
        )
        for p in el.findall("ControlPoint")
    )
    knots = tuple(ctx.num(k, "value") for k in el.findall("Knot"))
    if not 2 <= order <= len(points):
        raise HiyariError(
            f"{ctx.where(el)}: NURBS order {order} needs 2 .. {len(points)} (the control points)"
        )
    if len(knots) != len(points) + order:
        raise HiyariError(
            f"{ctx.where(el)}: a NURBS of order {order} with {len(points)} control points needs "
            f"{len(points) + order} knots, not {len(knots)}"
        )
    if any(b < a for a, b in zip(knots, knots[1:], strict=False)):
        raise HiyariError(f"{ctx.where(el)}: NURBS knots must not decrease")
    return Nurbs(order, points, knots)


_SHAPES = {
    "Polyline": _polyline,
    "Clothoid": _clothoid,
    "ClothoidSpline": _clothoid_spline,
    "Nurbs": _nurbs,
}
