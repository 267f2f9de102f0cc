"""A straightforward time-stepping simulation of the C&C driver, one scenario at a time.

This is the baseline the closed-form evaluator (:mod:`hiyari.risk.cc.evaluator`) is checked
and benchmarked against: plain Python floats, a fixed step (default 0.01 s), the driver's
judgements taken online from the simulated state, and contact tested on the two rectangles
at every step. It is deliberately written independently of the closed form, so agreement
between the two is evidence for both. Results carry the step's quantisation (event times to
``dt``, positions to about the closing speed x ``dt``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.kinematics import footprint_corners, overlap_depth
from hiyari.risk.cc.model import CCParams


@dataclass(frozen=True)
class SteppedResult:
    """Outcome of one stepped run: contact, smallest gap while overlapping laterally (m),
    first contact time (s, nan if none), closing speed at contact (m/s, nan if none)."""

    collision: bool
    min_gap_m: float
    t_collision_s: float
    impact_speed_mps: float


class _Ego:
    """Ego longitudinal state with the driver's (and optionally the AEB's) braking."""

    def __init__(self, v0: float, v_end: float, p: CCParams) -> None:
        self.v = v0
        self.x_front = 0.0
        self.v_end = v_end
        self.p = p
        self.brake_at = math.inf
        self.aeb_at = math.inf
        self.done = v0 <= v_end

    def decel(self, t: float) -> float:
        p = self.p
        d = 0.0
        if t >= self.brake_at:
            d = min(p.max_decel_mps2, p.max_decel_mps2 * (t - self.brake_at) / p.ramp_time_s)
        if t >= self.aeb_at:
            ramp = p.aeb_decel_mps2 * (t - self.aeb_at) / max(p.aeb_ramp_time_s, 1e-12)
            d = max(d, min(p.aeb_decel_mps2, ramp))
        return d

    def step(self, t: float, dt: float) -> None:
        if self.done:
            self.x_front += self.v * dt
            return
        # average deceleration over the step (the ramp is linear, so this is exact for it)
        d = 0.5 * (self.decel(t) + self.decel(t + dt))
        v_new = self.v - d * dt
        if v_new <= self.v_end:
            # stop braking part-way through the step at v_end
            frac = (self.v - self.v_end) / (d * dt) if d > 0 else 1.0
            self.x_front += 0.5 * (self.v + self.v_end) * dt * frac + self.v_end * dt * (1 - frac)
            self.v = self.v_end
            self.done = True
        else:
            self.x_front += 0.5 * (self.v + v_new) * dt
            self.v = v_new


def _x_extent_in_band(poly: list, half_width: float) -> tuple[float, float]:
    """Smallest and largest x of the polygon's part inside |y| <= half_width ((inf, -inf) if
    none), by clipping each edge to the band."""
    lo_x, hi_x = math.inf, -math.inf
    for (xa, ya), (xb, yb) in zip(poly, poly[1:] + poly[:1], strict=True):
        if ya == yb:
            if abs(ya) <= half_width:
                lo_x, hi_x = min(lo_x, xa, xb), max(hi_x, xa, xb)
            continue
        u1, u2 = (-half_width - ya) / (yb - ya), (half_width - ya) / (yb - ya)
        lo, hi = max(0.0, min(u1, u2)), min(1.0, max(u1, u2))
        if lo <= hi:
            xl, xh = xa + lo * (xb - xa), xa + hi * (xb - xa)
            lo_x, hi_x = min(lo_x, xl, xh), max(hi_x, xl, xh)
    return lo_x, hi_x


class _OtherShape:
    """The cut-in vehicle's corners relative to its centre: turned by ``yaw`` while it moves
    laterally, along the lane once centred in the ego lane (from the kinematics kernel, once;
    the loop only translates them)."""

    def __init__(self, yaw: float, p: CCParams) -> None:
        self.p = p
        shape = [
            footprint_corners(np.zeros(2), h, p.other_length_m, p.other_width_m) for h in (yaw, 0.0)
        ]
        self.moving, self.settled = (k.tolist() for k in shape)
        self.lowest = min(b for _, b in self.moving)  # its lowest corner below its centre

    def corners(self, x_rear: float, y: float) -> list[tuple[float, float]]:
        """Its corners with the rear (lane-aligned) at ``x_rear`` and the centre at ``y``."""
        cx = x_rear + 0.5 * self.p.other_length_m
        return [(cx + a, y + b) for a, b in (self.moving if y > 0 else self.settled)]

    def in_band(self, x_rear: float, y: float) -> tuple[float, float]:
        """Nearest and farthest x of its part inside the ego's band (nan when none)."""
        p = self.p
        half_w = 0.5 * p.ego_width_m
        if y <= 0:  # centred in the ego lane and along it: all of it is in the band
            return x_rear, x_rear + p.other_length_m
        if y + self.lowest > half_w:  # all of it still to the side of the band
            return math.nan, math.nan
        nearest, farthest = _x_extent_in_band(self.corners(x_rear, y), half_w)
        if not math.isfinite(nearest):
            return math.nan, math.nan
        return nearest, farthest


@dataclass
class _Judgement:
    """The C&C driver's online cut-in judgements: lane-change judgement at ``wander_m``,
    danger as ``p.judgement`` says, the decision taken once at danger."""

    p: CCParams
    judged_at: float = math.inf
    overlap_at: float = math.inf
    decided: bool = False
    watching: bool = False  # waiting for TTC to fall below ttc_brake_s

    def danger(self, t: float, shift: float, overlapping: bool) -> bool:
        p = self.p
        if shift >= p.wander_m and self.judged_at == math.inf:
            self.judged_at = t
        if overlapping and self.overlap_at == math.inf:
            self.overlap_at = t
        if p.judgement == "time":
            return t >= self.judged_at + p.perception_time_s - 1e-12
        if p.judgement == "position":
            return shift >= p.wander_m + p.danger_lateral_m - 1e-12
        return t >= self.overlap_at


def simulate_cut_in(
    ve0: float,
    vo0: float,
    dx0: float,
    vy: float,
    p: CCParams,
    dt: float = 0.01,
    t_max: float = 60.0,
) -> SteppedResult:
    """Cut-in (SI units, as :func:`~hiyari.risk.cc.evaluator.evaluate_cut_in`) by stepping.

    The other vehicle's rectangle is turned along its velocity while it moves laterally
    (``contact="heading"``) or kept along the lane; contact is the two rectangles overlapping
    (separating axes, :func:`hiyari.kinematics.overlap_depth`) by more than
    ``contact_tol_m``. ``min_gap_m``: the smallest distance from the ego's front to the
    other's nearest point inside the ego's width while they overlap laterally (the
    lane-aligned gap when the scenario ends before they do).
    """
    ego = _Ego(ve0, vo0, p)
    shape = _OtherShape(-math.atan2(vy, vo0) if p.contact == "heading" else 0.0, p)
    y_other = p.lane_width_m
    driver = _Judgement(p)
    t = 0.0
    min_gap = math.inf
    while t < t_max:
        x_rear = dx0 + vo0 * t
        gap = x_rear - ego.x_front
        nearest, farthest = shape.in_band(x_rear, y_other)
        inside = math.isfinite(nearest)
        closing = ego.v - vo0
        if driver.danger(t, p.lane_width_m - y_other, inside) and not driver.decided:
            driver.decided = True
            # at danger judgement: beside the ego (gap <= 0) it does not brake for it at all
            driver.watching = gap > 0
            above = closing <= 0 or gap >= p.ttc_brake_s * closing
            if driver.watching and above and p.above_ttc == "end":
                return SteppedResult(False, min(min_gap, gap), math.nan, math.nan)
        if driver.watching and closing > 0 and gap < p.ttc_brake_s * closing + 1e-12:
            driver.watching = False
            ego.brake_at = t + p.reaction_delay_s
        if inside:
            min_gap = min(min_gap, nearest - ego.x_front)
            if p.aeb and ego.aeb_at == math.inf and 0 <= gap < p.aeb_ttc_s * closing:
                ego.aeb_at = t + p.aeb_delay_s
            if _touching(ego, shape, x_rear, y_other, (nearest, farthest)):
                return SteppedResult(True, min_gap, t, closing)
            past = ego.x_front - p.ego_length_m >= x_rear + p.other_length_m
            if y_other <= 0 and (ego.done or past):
                break  # nothing changes any more: at Vo0 behind it, or past it and not slower
        ego.step(t, dt)
        y_other = max(0.0, y_other - vy * dt)
        t += dt
    return SteppedResult(False, min_gap, math.nan, math.nan)


def _touching(
    ego: _Ego, shape: _OtherShape, x_rear: float, y: float, extent: tuple[float, float]
) -> bool:
    """The two rectangles overlap by more than ``contact_tol_m``: only tested (separating
    axes on the corners) when the other's ``extent`` in the ego's band reaches into it."""
    p = shape.p
    if not (extent[0] < ego.x_front and extent[1] > ego.x_front - p.ego_length_m):
        return False
    mine = footprint_corners(
        np.array([ego.x_front - 0.5 * p.ego_length_m, 0.0]), 0.0, p.ego_length_m, p.ego_width_m
    )
    depth = overlap_depth(mine[None], np.array(shape.corners(x_rear, y))[None])
    return float(depth[0]) > p.contact_tol_m


def simulate_cut_out(
    ve0: float, vy: float, dx0_f: float, p: CCParams, dt: float = 0.01, t_max: float = 60.0
) -> SteppedResult:
    """Cut-out (as :func:`~hiyari.risk.cc.evaluator.evaluate_cut_out`) by stepping."""
    ego = _Ego(ve0, 0.0, p)
    distance = p.thw_s * ve0 + p.other_length_m + dx0_f
    half_w = 0.5 * (p.ego_width_m + p.other_width_m)
    shift = 0.0
    t = 0.0
    judged_at = math.inf
    min_gap = math.inf
    while t < t_max:
        gap = distance - ego.x_front
        min_gap = min(min_gap, gap)
        if gap < -p.contact_tol_m:
            return SteppedResult(True, gap, t, ego.v)
        if ego.done:
            break
        if shift >= p.wander_m and judged_at == math.inf:
            judged_at = t
        if not p.cut_out_perception:
            danger = t >= judged_at
        elif p.judgement == "position":
            danger = shift >= p.wander_m + p.danger_lateral_m - 1e-12
        else:
            danger = t >= judged_at + p.perception_time_s - 1e-12
        if danger and ego.brake_at == math.inf:
            ego.brake_at = t + p.reaction_delay_s
        revealed = shift >= half_w - 1e-12
        if p.aeb and revealed and ego.aeb_at == math.inf and gap < p.aeb_ttc_s * ego.v:
            ego.aeb_at = t + p.aeb_delay_s
        ego.step(t, dt)
        shift = min(p.lane_width_m, shift + vy * dt)
        t += dt
    return SteppedResult(False, min_gap, math.nan, math.nan)


def simulate_decel(
    ve0: float,
    gx: float,
    p: CCParams,
    dx0: float | None = None,
    dt: float = 0.01,
    t_max: float = 60.0,
) -> SteppedResult:
    """Deceleration (as :func:`~hiyari.risk.cc.evaluator.evaluate_decel`) by stepping."""
    ego = _Ego(ve0, 0.0, p)
    a_lead = gx * p.g_mps2
    perceive = {
        "always": True,
        "never": False,
        "hard-braking": a_lead > p.hard_braking_mps2,
    }[p.decel_perception]
    ego.brake_at = (p.perception_time_s if perceive else 0.0) + p.reaction_delay_s
    x_lead = p.thw_s * ve0 if dx0 is None else dx0
    v_lead = ve0
    t = 0.0
    min_gap = math.inf
    while t < t_max:
        gap = x_lead - ego.x_front
        min_gap = min(min_gap, gap)
        closing = ego.v - v_lead
        if gap < -p.contact_tol_m:
            return SteppedResult(True, gap, t, closing)
        if ego.done and v_lead == 0:
            break
        if p.aeb and ego.aeb_at == math.inf and gap < p.aeb_ttc_s * closing:
            ego.aeb_at = t + p.aeb_delay_s
        ego.step(t, dt)
        v_new = max(0.0, v_lead - a_lead * dt)
        x_lead += 0.5 * (v_lead + v_new) * dt if v_new > 0 else v_lead**2 / (2 * a_lead)
        v_lead = v_new
        t += dt
    return SteppedResult(False, min_gap, math.nan, math.nan)
