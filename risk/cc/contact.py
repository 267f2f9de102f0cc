"""Where the cut-in vehicle's rectangle reaches into the ego's lateral band, exactly, over time.

The ego drives centred in its lane: its rectangle covers the lateral band |y| <= ego_width / 2
and, longitudinally, [x_front - ego_length, x_front]. A convex polygon touches it iff the part
of the polygon inside that band reaches longitudinally into [x_front - ego_length, x_front].
So all that contact needs of the other vehicle is, at each time, the x-extent of its rectangle
clipped to the ego's band: its nearest point ``rear(t)`` and farthest point ``front(t)``.

In the Annex G cut-in the other vehicle's rectangle translates at (Vo0, -Vy) with a fixed
heading (along its velocity, ``contact="heading"``, or along the lane, ``contact="lane"``)
until it is centred in the ego lane, where its heading steps back to the lane's. While it
translates, the clipped extent changes slope only when a corner crosses a band edge, so
``rear`` and ``front`` are piecewise linear in time with knots at those crossings (at most
eight) and a jump at the heading step: :func:`cut_in_contact` returns them as
:class:`~hiyari.risk.cc.kinematics.Motion` objects, exact and vectorised over scenarios.

Frame: x along the road (m), 0 = the ego's front at t = 0; y lateral (m, left positive),
0 = the ego lane centre; t (s) from the start of the lateral motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.kinematics import footprint_corners
from hiyari.risk.cc.kinematics import Motion
from hiyari.risk.cc.model import CCParams

_TOUCH_M = 1e-9


def rectangle_band_x_extent(
    cx: np.ndarray,
    cy: np.ndarray,
    heading: np.ndarray,
    length: float,
    width: float,
    y_lo: float,
    y_hi: float,
) -> tuple[np.ndarray, np.ndarray]:
    """x-extent (m) of rectangles clipped to the band y_lo <= y <= y_hi; nan where they miss it.

    Rectangles centred at (cx, cy) (m), ``length`` x ``width`` (m), facing ``heading`` (rad
    from +x, |heading| < pi / 2); arrays broadcast. Exact: the left boundary of such a
    rectangle, x as a function of y, is convex with its minimum at the rearmost corner, so the
    clipped minimum is that corner or the left boundary at the nearer band edge; likewise the
    right boundary is concave with the foremost corner. A heading > 0 is the mirror image
    (y -> -y) of one < 0.
    """
    heading = np.asarray(heading, dtype=float)
    mirror = heading > 0
    dy = np.where(mirror, -np.asarray(cy, dtype=float), cy)
    lo = np.where(mirror, -y_hi, y_lo) - dy  # band relative to the centre
    hi = np.where(mirror, -y_lo, y_hi) - dy
    # corners relative to the centre of the (mirrored) rectangle turned right: front-left is
    # the foremost, rear-left the highest, rear-right the rearmost, front-right the lowest
    k = footprint_corners(np.zeros((*heading.shape, 2)), -np.abs(heading), length, width)
    fl, rl, rr, fr = ((k[..., i, 0], k[..., i, 1]) for i in range(4))
    y0, y1 = np.maximum(lo, fr[1]), np.minimum(hi, rl[1])

    def along(a: tuple, b: tuple, y: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            u = np.where(b[1] != a[1], (y - a[1]) / (b[1] - a[1]), 0.0)
        return a[0] + u * (b[0] - a[0])

    x_min = np.where(rr[1] > y1, along(fr, rr, y1), np.where(rr[1] < y0, along(rr, rl, y0), rr[0]))
    x_max = np.where(fl[1] > y1, along(fr, fl, y1), np.where(fl[1] < y0, along(fl, rl, y0), fl[0]))
    miss = y0 > y1
    cx = np.asarray(cx, dtype=float)
    return np.where(miss, np.nan, cx + x_min), np.where(miss, np.nan, cx + x_max)


def cut_in_heading(vo0: np.ndarray, vy: np.ndarray, p: CCParams) -> np.ndarray:
    """The cut-in vehicle's heading during its lateral motion (rad, negative = toward the ego
    lane on its right): along its velocity (Annex G) or 0 with ``contact="lane"``."""
    if p.contact == "lane":
        return np.zeros(np.shape(vo0))
    return -np.arctan2(vy, vo0)


@dataclass(frozen=True)
class CutInContact:
    """The cut-in vehicle as the ego's band sees it, for N scenarios.

    ``rear``/``front``: the nearest / farthest x (m) of its rectangle inside the ego's band,
    valid from ``t_overlap`` on (before, the motions are extrapolations of no meaning);
    ``t_overlap``: first lateral overlap (s); ``t_settle``: end of the lateral motion, when
    the heading steps back to the lane's (s); ``heading``: heading during the motion (rad);
    ``rear_receding``: ``rear`` never gains on the vehicle's centre while it moves laterally
    (its part in the band only grows backwards), so it moves at most at Vo0 throughout.
    """

    rear: Motion
    front: Motion
    t_overlap: np.ndarray
    t_settle: np.ndarray
    heading: np.ndarray
    rear_receding: np.ndarray

    def shifted(self, dx: np.ndarray) -> CutInContact:
        """The same cut-ins started ``dx`` (N,) metres further ahead."""
        return CutInContact(
            self.rear.shifted(dx),
            self.front.shifted(dx),
            self.t_overlap,
            self.t_settle,
            self.heading,
            self.rear_receding,
        )

    def rows(self, index: np.ndarray) -> CutInContact:
        """The cut-ins of the given rows."""
        return CutInContact(
            self.rear.rows(index),
            self.front.rows(index),
            self.t_overlap[index],
            self.t_settle[index],
            self.heading[index],
            self.rear_receding[index],
        )


def cut_in_contact(vo0: np.ndarray, dx0: np.ndarray, vy: np.ndarray, p: CCParams) -> CutInContact:
    """Exact band-clipped extent of the cut-in vehicle over time (module docstring); with
    ``contact="lane"`` simply its lane-aligned rear and front from the overlap on."""
    if p.contact == "lane":
        vo0, dx0, vy = (np.asarray(a, dtype=float) for a in (vo0, dx0, vy))
        rear = Motion.constant_speed(vo0, dx0)
        front = Motion.constant_speed(vo0, dx0 + p.other_length_m)
        return CutInContact(
            rear,
            front,
            p.cut_in_dy0_m / vy,
            p.lane_width_m / vy,
            np.zeros(vo0.shape),
            np.ones(vo0.shape, bool),
        )
    vo0, dx0, vy = (np.asarray(a, dtype=float) for a in (vo0, dx0, vy))
    w, half = p.lane_width_m, 0.5 * p.ego_width_m
    heading = cut_in_heading(vo0, vy, p)
    L, W = p.other_length_m, p.other_width_m
    oy = footprint_corners(np.zeros((*heading.shape, 2)), heading, L, W)[..., 1]  # (N, 4)
    t_settle = w / vy
    # centre height at which the lowest corner reaches the band's top edge
    t_overlap = np.clip((w - (half - oy.min(axis=1))) / vy, 0.0, t_settle)
    # a corner crossing a band edge: centre height +-half - its offset
    cross = np.concatenate([(half - oy), (-half - oy)], axis=1)
    t_cross = (w - cross) / vy[:, None]
    inner = (t_cross > t_overlap[:, None]) & (t_cross < t_settle[:, None])
    width = int(np.max(inner.sum(axis=1), initial=0))  # columns past it are all t_settle
    knots = np.sort(np.where(inner, t_cross, t_settle[:, None]), axis=1)[:, :width]
    knots = np.concatenate([t_overlap[:, None], knots, t_settle[:, None]], axis=1)
    yc = w - vy[:, None] * knots
    x_min, x_max = rectangle_band_x_extent(0.0, yc, heading[:, None], L, W, -half, half)
    # at t_overlap a corner (or edge) only touches the band: widen it by a hair there
    first_min, first_max = rectangle_band_x_extent(
        0.0, yc[:, 0], heading, L, W, -half - _TOUCH_M, half + _TOUCH_M
    )
    x_min[:, 0], x_max[:, 0] = first_min, first_max
    centre0 = dx0 + 0.5 * p.other_length_m
    rear = _piecewise_linear(knots, x_min, centre0, vo0, t_settle, -0.5 * p.other_length_m)
    front = _piecewise_linear(knots, x_max, centre0, vo0, t_settle, 0.5 * p.other_length_m)
    receding = np.all(np.diff(x_min, axis=1) <= 0, axis=1)
    return CutInContact(rear, front, t_overlap, t_settle, heading, receding)


def _piecewise_linear(
    knots: np.ndarray,
    offset: np.ndarray,
    centre0: np.ndarray,
    vo0: np.ndarray,
    t_settle: np.ndarray,
    settled_offset: float,
) -> Motion:
    """Motion of ``centre x + offset``: linear between ``knots`` (N, M) with the given offsets
    there, from t = 0 (the first piece extended back), then ``settled_offset`` from
    ``t_settle`` on (the heading step)."""
    dt = np.diff(knots, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(dt > 0, np.diff(offset, axis=1) / np.where(dt > 0, dt, 1.0), 0.0)
    v = vo0[:, None] + slope  # (N, M - 1)
    x = centre0[:, None] + vo0[:, None] * knots[:, :-1] + offset[:, :-1]
    starts = knots[:, :-1].copy()
    # the first piece from t = 0 (extrapolated: only values from t_overlap on are used)
    x[:, 0] -= v[:, 0] * starts[:, 0]
    starts[:, 0] = 0.0
    settled_x = centre0 + vo0 * t_settle + settled_offset
    zeros = np.zeros((knots.shape[0], knots.shape[1]))
    return Motion(
        t=np.concatenate([starts, t_settle[:, None]], axis=1),
        x=np.concatenate([x, settled_x[:, None]], axis=1),
        v=np.concatenate([v, vo0[:, None]], axis=1),
        a=zeros,
        j=zeros,
    )
