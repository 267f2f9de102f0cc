"""Trajectory shapes sampled into paths against closed forms: a clothoid of constant
curvature is a circular arc, a clothoid's heading is h0 + k0 s + k' s^2 / 2, clothoid-spline
pieces join end to start, a rational quadratic NURBS with weight sqrt(2)/2 is a quarter
circle, polyline times and headings come from the vertices, and TrajectoryPosition resolves
s along the path and t to its left."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from hiyari.bridge.openscenario.engine.paths.trajectory import (
    bspline_basis,
    clothoid_points,
    sample_trajectory,
)
from hiyari.bridge.openscenario.model.positions import WorldPosition
from hiyari.bridge.openscenario.model.trajectories import (
    Clothoid,
    ClothoidSpline,
    ClothoidSplineSegment,
    ControlPoint,
    Nurbs,
    Polyline,
    Trajectory,
    Vertex,
)


@dataclass
class _P:
    x: float
    y: float
    h: float


def _resolve(p: WorldPosition) -> _P:
    return _P(p.x, p.y, p.h)


def test_constant_curvature_clothoid_is_an_arc() -> None:
    r = 9.0
    xy, h, _ = clothoid_points(0.0, 0.0, 0.0, 1 / r, 0.0, r * math.pi / 2)  # a quarter turn left
    radius = np.hypot(xy[:, 0], xy[:, 1] - r)
    assert np.abs(radius - r).max() < 1e-9
    assert xy[-1] == pytest.approx([r, r], abs=1e-9) and h[-1] == pytest.approx(math.pi / 2)
    chords = np.hypot(*np.diff(xy, axis=0).T)
    assert np.ptp(chords[:-1]) < 1e-12 and chords.max() <= 0.25  # even spacing


def test_clothoid_heading_and_end_point() -> None:
    k0, kp, length = 0.01, 0.002, 40.0
    traj = Trajectory("c", Clothoid(WorldPosition(5.0, -2.0, 0.0, 0.3), k0, length, kp, 0.0, 8.0))
    path = sample_trajectory(traj, _resolve, None)
    s = path.s
    assert path.length == pytest.approx(length, rel=1e-6)
    assert path.h == pytest.approx(0.3 + k0 * s + 0.5 * kp * s * s, abs=1e-9)
    # the end point by a fine independent quadrature (midpoint rule, 1 mm steps)
    u = (np.arange(40000) + 0.5) * 1e-3
    hh = 0.3 + k0 * u + 0.5 * kp * u * u
    end = [5.0 + np.cos(hh).sum() * 1e-3, -2.0 + np.sin(hh).sum() * 1e-3]
    assert path.xy[-1] == pytest.approx(end, abs=1e-6)
    assert path.times[-1] == 8.0 and path.time_at(length / 2) == pytest.approx(4.0, rel=1e-6)


def test_clothoid_spline_pieces_join_and_start_at_the_entity() -> None:
    segs = (
        ClothoidSplineSegment(0.0, 0.0, 10.0),  # straight
        ClothoidSplineSegment(0.0, 0.1, 10.0),  # a clothoid into a turn
        ClothoidSplineSegment(0.1, 0.1, 5.0, h_offset=0.0, position_start=None),
    )
    traj = Trajectory("s", ClothoidSpline(segs))
    with pytest.raises(Exception, match="names no start position"):
        sample_trajectory(traj, _resolve, None)
    path = sample_trajectory(traj, _resolve, _P(1.0, 2.0, 0.0))
    assert path.xy[0] == pytest.approx([1.0, 2.0]) and path.length == pytest.approx(25.0, rel=1e-6)
    # heading: 0 over 10 m, then + 0.1 * 10 / 2 = 0.5 at the clothoid's end, then + 0.1 * 5
    k = np.searchsorted(path.s, 20.0)
    assert path.h[k] == pytest.approx(0.5, abs=1e-9) and path.h[-1] == pytest.approx(1.0, abs=1e-9)
    assert np.hypot(*np.diff(path.xy, axis=0).T).max() <= 0.25 + 1e-9  # no gap at the joints


def test_rational_nurbs_quarter_circle() -> None:
    w = math.sqrt(2) / 2
    pts = (ControlPoint(WorldPosition(1, 0), 0.0, 1.0), ControlPoint(WorldPosition(1, 1), None, w),
           ControlPoint(WorldPosition(0, 1), 2.0, 1.0))  # fmt: skip
    path = sample_trajectory(Trajectory("n", Nurbs(3, pts, (0, 0, 0, 1, 1, 1))), _resolve, None)
    assert np.abs(np.hypot(*path.xy.T) - 1.0).max() < 1e-12
    assert path.times is None  # a control point without a time: untimed
    assert bspline_basis(np.array([0, 0, 0, 1, 2, 3, 3, 3.0]), 3, np.linspace(0, 3, 31)).sum(
        1
    ) == pytest.approx(1.0)


def test_polyline_times_headings_and_offsets() -> None:
    verts = (
        Vertex(1.0, WorldPosition(0, 0, 0, 0.0)),
        Vertex(3.0, WorldPosition(10, 0, 0, math.pi / 2)),
    )
    path = sample_trajectory(Trajectory("p", Polyline(verts), closed=False), _resolve, None)
    assert path.s_at_time(2.0) == pytest.approx(5.0)
    x, y, h = path.pose(5.0, t=1.5)
    assert (x, y) == pytest.approx((5.0, 1.5)) and h == pytest.approx(math.pi / 4)
    assert path.project(7.0, -2.0) == pytest.approx((7.0, -2.0))
