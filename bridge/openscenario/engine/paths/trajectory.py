"""Trajectory shapes sampled into paths.

Polyline: straight between the vertices, headings from the vertex positions (their
orientation, else the road's direction there). Clothoid and clothoid-spline pieces: the
heading is h0 + k0 s + k' s^2 / 2 exactly and the position its integral, by Simpson's rule on
each 0.05 m step (error far below a micrometre per metre at the curvatures of roads), sampled every
0.25 m (a chord of 0.25 m on a 9 m radius is within 0.9 mm of the arc). NURBS: the rational
B-spline of the control points (de Boor), 20 samples per knot span and control point; the
heading is the curve's tangent. Times (trajectory time, s) are interpolated linearly in s
between the times the shape gives, and the path is untimed when it gives none.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from hiyari.bridge.openscenario.engine.paths.sampled import SampledPath
from hiyari.bridge.openscenario.model.positions import Position
from hiyari.bridge.openscenario.model.trajectories import (
    Clothoid,
    ClothoidSpline,
    Nurbs,
    Polyline,
    Trajectory,
)
from hiyari.errors import HiyariError

#: Integration step and sample spacing along clothoid pieces, m.
INTEGRATION_STEP = 0.05
SAMPLE_STEP = 0.25
#: NURBS samples per control point.
NURBS_SAMPLES = 20


class _Posed:
    """What a resolver gives: x, y (m) and heading h (rad) at least."""

    x: float
    y: float
    h: float


Resolve = Callable[[Position], _Posed]


def sample_trajectory(traj: Trajectory, resolve: Resolve, start: _Posed | None) -> SampledPath:
    """The path of ``traj``; ``resolve`` turns its positions into poses and ``start`` is where
    the entity is (the start of a clothoid spline whose first piece names none)."""
    shape = traj.shape
    if isinstance(shape, Polyline):
        path = _polyline(shape, resolve)
    elif isinstance(shape, Clothoid):
        p = resolve(shape.position)
        xy, h, s = clothoid_points(
            p.x, p.y, p.h, shape.curvature, shape.curvature_prime, shape.length
        )
        times = _linear_times(shape.start_time, shape.stop_time, len(h))
        path = SampledPath.through(xy, h, times, s)
    elif isinstance(shape, ClothoidSpline):
        path = _spline(traj.name, shape, resolve, start)
    else:
        path = _nurbs(shape, resolve)
    if traj.closed and path.length > 0:
        first = path.xy[:1]
        times = None if path.times is None else np.append(path.times, path.times[-1])
        path = SampledPath.through(np.vstack([path.xy, first]), np.append(path.h, path.h[0]), times)
    return path


def clothoid_points(
    x0: float, y0: float, h0: float, k0: float, k_prime: float, length: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (n, 2) every SAMPLE_STEP m (and the end), headings (n,) and arc lengths (n,) along the clothoid
    from (x0, y0) heading h0 whose curvature starts at k0 (1/m) and changes by ``k_prime``
    per metre, over ``length`` m."""
    n_int = max(2, math.ceil(length / INTEGRATION_STEP))
    step = length / n_int
    s = np.linspace(0.0, length, n_int + 1)

    def heading(u: np.ndarray) -> np.ndarray:
        return h0 + k0 * u + 0.5 * k_prime * u * u

    h = heading(s)
    hm = heading(s[:-1] + 0.5 * step)
    # Simpson's rule on each step with its midpoint
    dx = step / 6 * (np.cos(h[:-1]) + 4 * np.cos(hm) + np.cos(h[1:]))
    dy = step / 6 * (np.sin(h[:-1]) + 4 * np.sin(hm) + np.sin(h[1:]))
    x = x0 + np.concatenate([[0.0], np.cumsum(dx)])
    y = y0 + np.concatenate([[0.0], np.cumsum(dy)])
    every = max(1, round(SAMPLE_STEP / step))
    keep = np.unique(np.append(np.arange(0, n_int + 1, every), n_int))
    return np.column_stack([x[keep], y[keep]]), h[keep], s[keep]


def _linear_times(t0: float | None, t1: float | None, n: int) -> np.ndarray | None:
    if t0 is None or t1 is None:
        return None
    return np.linspace(t0, t1, n)


def _polyline(shape: Polyline, resolve: Resolve) -> SampledPath:
    poses = [resolve(v.position) for v in shape.vertices]
    xy = np.array([[p.x, p.y] for p in poses])
    vt = [v.time for v in shape.vertices]
    times = np.array(vt, dtype=float) if all(t is not None for t in vt) else None
    if times is not None and np.any(np.diff(times) < 0):
        raise HiyariError("polyline vertex times must not decrease")
    return SampledPath.through(xy, np.array([p.h for p in poses]), times)


def _spline(
    name: str, shape: ClothoidSpline, resolve: Resolve, start: _Posed | None
) -> SampledPath:
    pts, hs, arcs, seg_ends = [], [], [], []
    done = 0.0
    x = y = h = 0.0
    for k, seg in enumerate(shape.segments):
        if seg.position_start is not None:
            p = resolve(seg.position_start)
            x, y, h = p.x, p.y, p.h
        elif k == 0:
            if start is None:
                raise HiyariError(
                    f"trajectory {name!r}: its clothoid spline names no start position and no "
                    "entity follows it here"
                )
            x, y, h = start.x, start.y, start.h
        h += seg.h_offset
        k_prime = (seg.curvature_end - seg.curvature_start) / seg.length
        xy, hh, ss = clothoid_points(x, y, h, seg.curvature_start, k_prime, seg.length)
        first = 0 if k == 0 else 1  # the joint once
        pts.append(xy[first:])
        hs.append(hh[first:])
        arcs.append(done + ss[first:])
        done += seg.length
        x, y, h = float(xy[-1, 0]), float(xy[-1, 1]), float(hh[-1])
        seg_ends.append(seg.length)
    xy, h_all, s = np.vstack(pts), np.concatenate(hs), np.concatenate(arcs)
    starts = [seg.time_start for seg in shape.segments]
    times = None
    if all(t is not None for t in starts) and shape.time_end is not None:
        # piecewise linear in s between the pieces' start times and the end time
        knots_s = np.concatenate([[0.0], np.cumsum(seg_ends)])
        knots_t = np.array([*starts, shape.time_end], dtype=float)
        times = np.interp(s, knots_s, knots_t)
    return SampledPath.through(xy, h_all, times, s)


def _nurbs(shape: Nurbs, resolve: Resolve) -> SampledPath:
    poses = [resolve(cp.position) for cp in shape.control_points]
    ctrl = np.array([[p.x, p.y] for p in poses])
    w = np.array([cp.weight for cp in shape.control_points])
    knots = np.array(shape.knots)
    order = shape.order
    lo, hi = knots[order - 1], knots[len(ctrl)]
    u = np.linspace(lo, hi, NURBS_SAMPLES * len(ctrl) + 1)
    basis = bspline_basis(knots, order, u)  # (m, n)
    wb = basis * w
    den = wb.sum(1)
    xy = (wb @ ctrl) / den[:, None]
    ct = [cp.time for cp in shape.control_points]
    times = None
    if all(t is not None for t in ct):
        times = (wb @ np.array(ct, dtype=float)) / den
    return SampledPath.through(xy, None, times)


def bspline_basis(knots: np.ndarray, order: int, u: np.ndarray) -> np.ndarray:
    """(len(u), n) B-spline basis functions of ``order`` (degree + 1) on ``knots``
    (n + order values) by the Cox-de Boor recursion; the last parameter value belongs to
    the last non-empty span."""
    n = len(knots) - order
    u = np.asarray(u, dtype=float)
    last = knots[n]
    b = np.zeros((len(u), len(knots) - 1))
    for i in range(len(knots) - 1):
        inside = (knots[i] <= u) & (u < knots[i + 1])
        if knots[i] < knots[i + 1] and knots[i + 1] == last:
            inside |= u == last
        b[:, i] = inside
    for p in range(1, order):
        nb = np.zeros((len(u), len(knots) - 1 - p))
        for i in range(len(knots) - 1 - p):
            d1 = knots[i + p] - knots[i]
            d2 = knots[i + p + 1] - knots[i + 1]
            if d1 > 0:
                nb[:, i] += (u - knots[i]) / d1 * b[:, i]
            if d2 > 0:
                nb[:, i] += (knots[i + p + 1] - u) / d2 * b[:, i + 1]
        b = nb
    return b[:, :n]
