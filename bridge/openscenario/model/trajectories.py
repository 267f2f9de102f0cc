"""Trajectories (polyline, clothoid, clothoid spline, NURBS) and routes. SI units: m, s, rad,
curvature 1/m (positive: turning left), its rate 1/m^2."""

from __future__ import annotations

from dataclasses import dataclass

from hiyari.bridge.openscenario.model.positions import Position

__all__ = [
    "Clothoid",
    "ClothoidSpline",
    "ClothoidSplineSegment",
    "ControlPoint",
    "Nurbs",
    "Polyline",
    "Route",
    "Trajectory",
    "TrajectoryShape",
    "Vertex",
]


@dataclass(frozen=True)
class Vertex:
    """A polyline vertex: ``time`` (s, None when the trajectory has no timing) and where."""

    time: float | None
    position: Position


@dataclass(frozen=True)
class Polyline:
    """Straight segments through the vertices."""

    vertices: tuple[Vertex, ...]


@dataclass(frozen=True)
class Clothoid:
    """A curve of ``length`` m from ``position`` (its heading the start heading) whose
    curvature starts at ``curvature`` and changes by ``curvature_prime`` per metre; passed
    from ``start_time`` to ``stop_time`` (s; None: no timing)."""

    position: Position
    curvature: float
    length: float
    curvature_prime: float = 0.0
    start_time: float | None = None
    stop_time: float | None = None


@dataclass(frozen=True)
class ClothoidSplineSegment:
    """One piece of a clothoid spline: curvature linear from ``curvature_start`` to
    ``curvature_end`` over ``length`` m; it starts at ``position_start`` (None: where the
    previous piece ends, or for the first piece where the entity is) turned by ``h_offset``
    rad, at ``time_start`` s (None: no timing)."""

    curvature_start: float
    curvature_end: float
    length: float
    h_offset: float = 0.0
    time_start: float | None = None
    position_start: Position | None = None


@dataclass(frozen=True)
class ClothoidSpline:
    """Clothoid pieces joined end to start; ``time_end``: time at the last piece's end."""

    segments: tuple[ClothoidSplineSegment, ...]
    time_end: float | None = None


@dataclass(frozen=True)
class ControlPoint:
    """A NURBS control point with its ``time`` (s; None: no timing) and ``weight``."""

    position: Position
    time: float | None = None
    weight: float = 1.0


@dataclass(frozen=True)
class Nurbs:
    """A non-uniform rational B-spline of ``order`` (degree + 1) with its knot vector
    (len(control points) + order values)."""

    order: int
    control_points: tuple[ControlPoint, ...]
    knots: tuple[float, ...]


TrajectoryShape = Polyline | Clothoid | ClothoidSpline | Nurbs


@dataclass(frozen=True)
class Trajectory:
    """A named trajectory; ``closed``: its end joins its start."""

    name: str
    shape: TrajectoryShape
    closed: bool = False


@dataclass(frozen=True)
class Route:
    """Waypoints to pass in order (the way between them along the roads: shortest by road
    length); ``closed``: the last leads back to the first."""

    name: str
    waypoints: tuple[Position, ...]
    closed: bool = False
