"""The kinematics kernel's gaps and extents, one rectangle or pair at a time, compiled.

:mod:`hiyari.kinematics`' array functions (:func:`~hiyari.kinematics.footprint_distance`,
:func:`~hiyari.kinematics.footprint_extent`, :func:`~hiyari.kinematics.box_distance`,
:func:`~hiyari.kinematics.rectangle_point_distance`) run the loops below, and compiled callers
(the OpenSCENARIO trigger kernel, one condition row at a time) call the scalar functions
directly: a gap is computed by one piece of code wherever it is measured.

Frames and units as in :mod:`hiyari.kinematics`: world x, y in metres, headings in radians
counter-clockwise from world +x, a rectangle by its centre, heading, length along the heading
and width across it. Functions that take ``c``, ``s`` are handed the cos and sin of a heading
their caller already has (the trigger kernel computes them once per entity and step).
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.jit import njit


# ---------------------------------------------------------------------------------- scalars
@njit(cache=True)
def unrotate(x: float, y: float, c: float, s: float) -> tuple[float, float]:
    """World-frame vector (``x``, ``y``) -> the (forward, left) components in the frame of a
    vehicle whose heading has cos ``c`` and sin ``s`` (kinematics.unrotate_xy)."""
    return x * c + y * s, -x * s + y * c


@njit(cache=True)
def max0(x: float) -> float:
    """max(x, 0) as np.maximum(x, 0.0): NaN stays NaN."""
    return x if (x > 0.0 or x != x) else 0.0


@njit(cache=True)
def outside(x: float, y: float, half_x: float, half_y: float) -> float:
    """Distance (m) from the point (``x``, ``y``) to the box |x| <= ``half_x``,
    |y| <= ``half_y`` (box frame); 0 inside."""
    lx, ly = max0(abs(x) - half_x), max0(abs(y) - half_y)
    if ly == 0.0:  # C99 F.9.4.3: hypot(x, 0) is fabs(x), exactly; saves the call
        return lx
    if lx == 0.0:
        return ly
    return math.hypot(lx, ly)


@njit(cache=True)
def footprint_extent(length: float, width: float, heading: float) -> tuple[float, float]:
    """Half extents (m) along a frame's x and y of a rectangle at ``heading`` (rad, relative
    to that frame): the half sizes of its axis-aligned bounding box."""
    c, s = abs(math.cos(heading)), abs(math.sin(heading))
    return (length * c + width * s) / 2, (length * s + width * c) / 2


@njit(cache=True)
def rectangle_point_distance(
    cx: float, cy: float, c: float, s: float, half_x: float, half_y: float, px: float, py: float
) -> float:
    """Distance (m) from the world point (``px``, ``py``) to the rectangle centred at
    (``cx``, ``cy``) whose heading has cos ``c`` and sin ``s``, half length ``half_x`` and
    half width ``half_y`` (m); 0 inside."""
    x, y = unrotate(px - cx, py - cy, c, s)
    return outside(x, y, half_x, half_y)


@njit(cache=True)
def footprint_distance_cs(
    ax_: float,
    ay_: float,
    ha: float,
    cha: float,
    sha: float,
    length_a: float,
    width_a: float,
    bx_: float,
    by_: float,
    hb: float,
    chb: float,
    shb: float,
    length_b: float,
    width_b: float,
) -> float:
    """Shortest distance (m) between oriented rectangles A and B (centres m, headings ``ha``,
    ``hb`` rad with their cos and sin, lengths and widths m); 0 when they touch or overlap.

    Two disjoint convex shapes are closest at a corner of one of them, so the distance is the
    least corner-to-rectangle distance both ways, each rectangle's corners taken in the other's
    frame; they overlap when no axis of either separates them.
    """
    dx, dy = bx_ - ax_, by_ - ay_
    la, wa, lb, wb = 0.5 * length_a, 0.5 * width_a, 0.5 * length_b, 0.5 * width_b
    c, s = math.cos(hb - ha), math.sin(hb - ha)  # B's axes in A's frame
    bx, by = unrotate(dx, dy, cha, sha)  # B's centre in A's frame
    ax, ay = unrotate(-dx, -dy, chb, shb)  # A's centre in B's frame
    lbc, lbs, wbc, wbs = lb * c, lb * s, wb * c, wb * s
    lac, las, wac, was = la * c, la * s, wa * c, wa * s
    ac, as_ = abs(c), abs(s)
    apart = (abs(bx) > la + lb * ac + wb * as_) or (abs(by) > wa + lb * as_ + wb * ac)
    apart = apart or (abs(ax) > lb + la * ac + wa * as_) or (abs(ay) > wb + la * as_ + wa * ac)
    if not apart:
        return 0.0
    b_in_a, a_in_b = math.inf, math.inf
    # corners: centre + sx * half length axis + sy * half width axis
    for sx, sy in ((1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)):
        xb, yb = bx + sx * lbc - sy * wbs, by + sx * lbs + sy * wbc
        xa, ya = ax + sx * lac + sy * was, ay - sx * las + sy * wac
        b_in_a = min(b_in_a, outside(xb, yb, la, wa))
        a_in_b = min(a_in_b, outside(xa, ya, lb, wb))
    return min(b_in_a, a_in_b)


@njit(cache=True)
def footprint_distance(
    ax: float,
    ay: float,
    ha: float,
    length_a: float,
    width_a: float,
    bx: float,
    by: float,
    hb: float,
    length_b: float,
    width_b: float,
) -> float:
    """:func:`footprint_distance_cs`, the cos and sin of the headings computed here."""
    return footprint_distance_cs(
        ax, ay, ha, math.cos(ha), math.sin(ha), length_a, width_a,
        bx, by, hb, math.cos(hb), math.sin(hb), length_b, width_b,
    )  # fmt: skip


# ---------------------------------------------------------------------------------- loops
# Over flat float64 arrays of one length (kinematics broadcasts and flattens them), into out.
@njit(cache=True)
def footprint_distance_rows(
    ax: np.ndarray,
    ay: np.ndarray,
    ha: np.ndarray,
    la: np.ndarray,
    wa: np.ndarray,
    bx: np.ndarray,
    by: np.ndarray,
    hb: np.ndarray,
    lb: np.ndarray,
    wb: np.ndarray,
    out: np.ndarray,
) -> None:
    """:func:`footprint_distance` of each row."""
    for k in range(len(out)):
        out[k] = footprint_distance(
            ax[k], ay[k], ha[k], la[k], wa[k], bx[k], by[k], hb[k], lb[k], wb[k]
        )


@njit(cache=True)
def footprint_extent_rows(
    length: np.ndarray, width: np.ndarray, heading: np.ndarray, ex: np.ndarray, ey: np.ndarray
) -> None:
    """:func:`footprint_extent` of each row, into ``ex`` and ``ey``."""
    for k in range(len(ex)):
        ex[k], ey[k] = footprint_extent(length[k], width[k], heading[k])


@njit(cache=True)
def rectangle_point_distance_rows(
    cx: np.ndarray,
    cy: np.ndarray,
    heading: np.ndarray,
    half_x: np.ndarray,
    half_y: np.ndarray,
    px: np.ndarray,
    py: np.ndarray,
    out: np.ndarray,
) -> None:
    """:func:`rectangle_point_distance` of each row (headings in rad)."""
    for k in range(len(out)):
        h = heading[k]
        out[k] = rectangle_point_distance(
            cx[k], cy[k], math.cos(h), math.sin(h), half_x[k], half_y[k], px[k], py[k]
        )


@njit(cache=True)
def box_distance_rows(
    x: np.ndarray, y: np.ndarray, half_x: np.ndarray, half_y: np.ndarray, out: np.ndarray
) -> None:
    """:func:`outside` of each row."""
    for k in range(len(out)):
        out[k] = outside(x[k], y[k], half_x[k], half_y[k])
