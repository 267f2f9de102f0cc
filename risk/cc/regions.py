"""Exact Unpreventable regions of the cut-in: every interval of initial gaps dx0 that collides.

For a cut-in (Ve0, Vo0, Vy) the colliding gaps are not one interval below a boundary: at
small gaps the ego may pass before the other car enters its lane, and at the gaps where it
brakes it may not. This module finds all of them.

Driver only (exact). The C&C ego's motion depends on dx0 only through its reaction time, and
that falls into three regimes of dx0 (closing speed dv = Ve0 - Vo0, danger judgement t_d):

- R0, dx0 <= dv t_d: the other car is beside the ego at danger judgement: no braking;
- R1, up to dv (t_d + ttc_brake_s): reaction at t_d;
- R2, beyond: no reaction and the scenario ends at t_d (``above_ttc="end"``, the default),
  or the reaction when TTC falls to ``ttc_brake_s`` (``"wait"``).

Where the ego's motion is fixed (R0, R1, R2 with "end"), contact at time t happens for dx0
in an open interval (A(t), B(t)) (the other car's extent in the ego's band shifted by dx0
against the ego), and over a stretch of time where A and B are continuous the union of those
intervals is (inf A, sup B): two stretches, split at the heading step when the lateral
motion ends, give at most two intervals per regime, from the exact minima of piecewise cubics.
In R2 with "wait" the ego reacts at t_r = dx0 / dv - ttc_brake_s, and the contact margin
max_t [F(t - t_r) - rear(t)] (F the ego's non-decreasing relative displacement) can only fall
as t_r grows: the colliding part of R2 is one interval at its low end (or all of it), whose
end is found by bisection on the exact evaluator to ``bisect_tol_m``.

With the AEB (whose trigger depends on the gap) the gaps inside the driver-only colliding
intervals are scanned and every change of outcome between scan points is bisected: an
interval narrower than the scan spacing can be missed there (:class:`RegionSearch`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from hiyari.risk.cc.contact import CutInContact, cut_in_contact
from hiyari.risk.cc.evaluator import CHUNK, cut_in_setup, ego_response, outcome
from hiyari.risk.cc.kinematics import PiecewiseCubic
from hiyari.risk.cc.model import CCParams

_MERGE_M = 1e-9  # intervals closer than this are one
_DEFAULT = CCParams()


@dataclass(frozen=True)
class RegionSearch:
    """Numerical settings. ``bisect_tol_m``: the end of the R2 interval (driver only) to
    this; the AEB scan takes ``max_scans`` points across each driver-only colliding interval
    (an unbounded one up to ``cap_m``) and bisects every change of outcome to ``aeb_tol_m``."""

    bisect_tol_m: float = 1e-6
    cap_m: float = 200.0
    max_scans: int = 16
    aeb_tol_m: float = 1e-4


_SEARCH = RegionSearch()


@dataclass(frozen=True)
class Regions:
    """Colliding gaps of N scenarios: intervals ``lo`` < dx0 < ``hi`` (m), (N, K) arrays
    sorted by ``lo``, padded with nan; ``hi`` may be inf (every larger gap collides). ``lo``
    is clipped at 0: an interval with ``lo`` = 0 includes dx0 = 0 (``hi`` = 0: only it)."""

    lo: np.ndarray
    hi: np.ndarray

    @property
    def count(self) -> np.ndarray:
        """Number of intervals per scenario."""
        return np.sum(~np.isnan(self.lo), axis=1)

    @property
    def upper(self) -> np.ndarray:
        """The Preventable boundary: the smallest dx0 (m) from which on no gap collides
        (0 where none does, inf where every large gap does)."""
        return np.nanmax(np.where(np.isnan(self.hi), 0.0, self.hi), axis=1, initial=0.0)

    def contains(self, dx0: np.ndarray) -> np.ndarray:
        """True where dx0 (one per scenario) lies in a colliding interval."""
        d = np.asarray(dx0, dtype=float).reshape(-1, 1)
        with np.errstate(invalid="ignore"):
            inside = ((d > self.lo) & (d < self.hi)) | ((self.lo == 0) & (d == 0))
            return np.any(inside, axis=1)

    def rows(self, index: np.ndarray) -> Regions:
        """The regions of the given scenarios."""
        return Regions(self.lo[index], self.hi[index])

    def intervals(self, i: int) -> list[tuple[float, float]]:
        """Scenario ``i``'s intervals as (lo, hi) pairs."""
        keep = ~np.isnan(self.lo[i])
        return list(zip(self.lo[i][keep].tolist(), self.hi[i][keep].tolist(), strict=True))


def merge_intervals(lo: np.ndarray, hi: np.ndarray) -> Regions:
    """Union of intervals per row (nan = none; empty ones dropped), as sorted disjoint
    :class:`Regions`; ``lo`` below 0 is clipped to 0 and intervals ending at or below 0 go."""
    # an interval closed at 0 from below (lo < 0 = hi) is the single colliding gap 0
    keep = ~np.isnan(lo) & ((hi > np.maximum(lo, 0.0)) | ((hi == 0) & (lo < 0)))
    lo = np.where(keep, np.maximum(lo, 0.0), np.nan)
    hi = np.where(np.isnan(lo), np.nan, hi)
    order = np.argsort(np.where(np.isnan(lo), np.inf, lo), axis=1)
    lo, hi = np.take_along_axis(lo, order, 1), np.take_along_axis(hi, order, 1)
    n, k = lo.shape
    out_lo, out_hi = np.full((n, k), np.nan), np.full((n, k), np.nan)
    cur_lo, cur_hi = lo[:, 0].copy(), hi[:, 0].copy()
    slot = np.zeros(n, dtype=int)
    rows = np.arange(n)
    for j in range(1, k):
        valid = ~np.isnan(lo[:, j])
        joins = valid & (lo[:, j] <= cur_hi + _MERGE_M)
        starts = valid & ~joins
        # close the current interval where a new one starts
        out_lo[rows[starts], slot[starts]] = cur_lo[starts]
        out_hi[rows[starts], slot[starts]] = cur_hi[starts]
        slot = slot + starts
        cur_hi = np.where(joins, np.maximum(cur_hi, hi[:, j]), np.where(starts, hi[:, j], cur_hi))
        cur_lo = np.where(starts, lo[:, j], cur_lo)
    have = ~np.isnan(cur_lo)
    out_lo[rows[have], slot[have]] = cur_lo[have]
    out_hi[rows[have], slot[have]] = cur_hi[have]
    width = max(int(np.max(np.sum(~np.isnan(out_lo), axis=1), initial=0)), 1)
    return Regions(out_lo[:, :width], out_hi[:, :width])


def _fixed_motion_intervals(
    ve0: np.ndarray,
    vo0: np.ndarray,
    vy: np.ndarray,
    contact: CutInContact,
    reaction: tuple[np.ndarray, np.ndarray],
    p: CCParams,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Colliding dx0 intervals when the ego's motion does not depend on dx0 (``reaction`` =
    its reaction start and the scenario end; ``contact`` at dx0 = 0): one per stretch of
    time on which the other car's band extent is continuous (before and after its heading
    step at the end of the lateral motion)."""
    zeros = np.zeros_like(ve0)
    setup = cut_in_setup(ve0, vo0, zeros, vy, p, reaction=reaction, contact=contact)
    ego, _ = ego_response(setup, p)
    tol = p.contact_tol_m
    front = PiecewiseCubic.gap(zeros, setup.contact_rear, ego)  # rear(t) - ego front at dx0 = 0
    back = PiecewiseCubic.gap(np.full(ve0.shape, -p.ego_length_m), ego, setup.contact_front)
    t0, t_end = contact.t_overlap, reaction[1]
    out = []
    for ts, te in (
        (t0, np.minimum(contact.t_settle, t_end)),
        (np.maximum(t0, contact.t_settle), t_end),
    ):
        hi = -front.minimum_between(ts, te) - tol
        lo = back.minimum_between(ts, te) + tol
        empty = ts > te
        out.append((np.where(empty, np.nan, lo), np.where(empty, np.nan, hi)))
    return out


def _clip(
    pair: tuple[np.ndarray, np.ndarray], lo_bound: np.ndarray, hi_bound: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Intersection of intervals with [lo_bound, hi_bound] (nan where empty)."""
    lo, hi = np.maximum(pair[0], lo_bound), np.minimum(pair[1], hi_bound)
    empty = ~(lo < hi)
    return np.where(empty, np.nan, lo), np.where(empty, np.nan, hi)


def _collides(
    ve0: np.ndarray,
    vo0: np.ndarray,
    dx0: np.ndarray,
    vy: np.ndarray,
    contact: CutInContact,
    p: CCParams,
) -> np.ndarray:
    """The evaluator's collision verdict at gaps ``dx0`` (``contact`` at dx0 = 0)."""
    out = np.empty(ve0.size, dtype=bool)
    for i in range(0, ve0.size, CHUNK):
        part = slice(i, i + CHUNK)
        moved = contact.rows(part).shifted(dx0[part])
        setup = cut_in_setup(ve0[part], vo0[part], dx0[part], vy[part], p, contact=moved)
        out[part] = outcome(setup, p).collision
    return out


def _bisect_last_colliding(
    collides: Callable[[np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray, tol: float
) -> np.ndarray:
    """Per row, the end of a colliding run that starts at ``lo`` and has ended by ``hi``."""
    lo, hi = lo.copy(), hi.copy()
    while lo.size and np.max(hi - lo) > tol:
        mid = 0.5 * (lo + hi)
        hit = collides(mid)
        lo = np.where(hit, mid, lo)
        hi = np.where(hit, hi, mid)
    return hi


def _r2_wait(
    ve0: np.ndarray,
    vo0: np.ndarray,
    vy: np.ndarray,
    contact: CutInContact,
    r2_lo: np.ndarray,
    p: CCParams,
    tol: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The colliding interval of regime R2 under ``above_ttc="wait"`` (one at its low end)."""
    n = ve0.size
    lo_out, hi_out = np.full(n, np.nan), np.full(n, np.nan)
    dv = ve0 - vo0
    todo = np.flatnonzero((dv > 0) & np.isfinite(r2_lo))
    if todo.size == 0:
        return lo_out, hi_out
    ve, vo, v, c = ve0[todo], vo0[todo], vy[todo], contact.rows(todo)
    # from this gap on the reaction comes after the lateral motion and the outcome is fixed
    span = p.ego_length_m + p.other_length_m
    far = dv[todo] * (np.maximum(c.t_settle, c.t_overlap) + p.ttc_brake_s + 1.0) + span
    far = np.maximum(far, r2_lo[todo] + 1.0)
    start = r2_lo[todo] + 0.5 * tol
    at_start = _collides(ve, vo, start, v, c, p)
    at_far = _collides(ve, vo, far, v, c, p)
    lo_out[todo[at_start]] = r2_lo[todo[at_start]]
    hi_out[todo[at_start & at_far]] = np.inf
    ends = np.flatnonzero(at_start & ~at_far)
    if ends.size:
        sub = (ve[ends], vo[ends], v[ends], c.rows(ends))
        hi_out[todo[ends]] = _bisect_last_colliding(
            lambda d: _collides(sub[0], sub[1], d, sub[2], sub[3], p), start[ends], far[ends], tol
        )
    return lo_out, hi_out


def _driver_regions(
    ve0: np.ndarray, vo0: np.ndarray, vy: np.ndarray, p: CCParams, search: RegionSearch
) -> Regions:
    never = np.full(ve0.shape, np.inf)
    contact = cut_in_contact(vo0, np.zeros_like(ve0), vy, p)
    t_d = p.danger_judgement_time(vy, contact.t_overlap)
    dv = ve0 - vo0
    closing = dv > 0
    a0 = np.where(closing, dv * t_d, 0.0)  # R0 up to here
    a1 = np.where(closing, dv * (t_d + p.ttc_brake_s), 0.0)  # R1 up to here
    # without closing speed there is no TTC: under "wait" no gap ever brings a reaction
    r0_top = np.where(closing | (p.above_ttc == "end"), a0, np.inf)

    def fixed(t_react: np.ndarray, t_end: np.ndarray) -> list:
        return _fixed_motion_intervals(ve0, vo0, vy, contact, (t_react, t_end), p)

    pairs = [_clip(q, np.full(ve0.shape, -np.inf), r0_top) for q in fixed(never, never)]
    pairs += [_clip(q, a0, a1) for q in fixed(t_d, never)]
    if p.above_ttc == "end":
        pairs += [_clip(q, a1, never) for q in fixed(never, t_d)]
    else:
        r2_lo = np.where(closing, a1, np.nan)
        pairs.append(_r2_wait(ve0, vo0, vy, contact, r2_lo, p, search.bisect_tol_m))
    lo = np.stack([q[0] for q in pairs], axis=1)
    hi = np.stack([q[1] for q in pairs], axis=1)
    return merge_intervals(lo, hi)


def _aeb_regions(
    ve0: np.ndarray, vo0: np.ndarray, vy: np.ndarray, p: CCParams, search: RegionSearch
) -> Regions:
    """Scan + bisection of every change of outcome along dx0 inside the driver-only colliding
    intervals. The AEB only brakes for an obstacle still ahead of the ego when they start to
    overlap, and braking more only keeps the ego further behind it, so it can only shrink
    those intervals (module docstring)."""
    driver = _driver_regions(ve0, vo0, vy, replace(p, aeb=False), search)
    rows, slot = np.nonzero(~np.isnan(driver.lo))
    if rows.size == 0:
        return driver
    d_lo = driver.lo[rows, slot]
    d_hi = np.minimum(driver.hi[rows, slot], np.maximum(search.cap_m, d_lo + 1.0))
    # scan points strictly inside each interval (its ends do not collide, except lo = 0)
    n_scan = max(int(search.max_scans), 2)
    frac = np.linspace(0.0, 1.0, n_scan)
    grid = d_lo[:, None] + (d_hi - d_lo)[:, None] * frac[None, :]
    grid[:, 0] = np.where(d_lo == 0, 0.0, d_lo + 0.5 * search.aeb_tol_m)
    grid[:, -1] = np.where(np.isinf(driver.hi[rows, slot]), d_hi, d_hi - 0.5 * search.aeb_tol_m)
    contact = cut_in_contact(vo0, np.zeros_like(ve0), vy, p)
    rep = np.repeat(rows, n_scan)
    hit = _collides(ve0[rep], vo0[rep], grid.reshape(-1), vy[rep], contact.rows(rep), p)
    hit = hit.reshape(rows.size, n_scan)
    # every change between neighbouring scan points, bisected together
    change = hit[:, 1:] != hit[:, :-1]
    k, cols = np.nonzero(change)
    lo_d, hi_d = grid[k, cols], grid[k, cols + 1]
    starts_hit = hit[k, cols]
    r = rows[k]
    sub = (ve0[r], vo0[r], vy[r], contact.rows(r))
    while k.size and np.max(hi_d - lo_d) > search.aeb_tol_m:
        mid = 0.5 * (lo_d + hi_d)
        same = _collides(sub[0], sub[1], mid, sub[2], sub[3], p) == starts_hit
        lo_d, hi_d = np.where(same, mid, lo_d), np.where(same, hi_d, mid)
    edge = np.full((rows.size, n_scan - 1), np.nan)
    edge[k, cols] = 0.5 * (lo_d + hi_d)
    # an interval opens at a change into collision (or at the scan's start) and closes at
    # the next change (or at the scan's end: the driver-only end, or on for an unbounded one)
    opens = np.where(change & hit[:, 1:], edge, np.nan)
    closes = np.where(change & hit[:, :-1], edge, np.nan)
    opens = np.concatenate([np.where(hit[:, :1], d_lo[:, None], np.nan), opens], axis=1)
    end = np.where(np.isinf(driver.hi[rows, slot]), np.inf, driver.hi[rows, slot])
    closes = np.concatenate([closes, np.where(hit[:, -1:], end[:, None], np.nan)], axis=1)
    # pair the k-th opening with the k-th closing; then gather per scenario
    opens, closes = np.sort(opens, axis=1), np.sort(closes, axis=1)
    width = opens.shape[1]
    lo = np.full((ve0.size, driver.lo.shape[1] * width), np.nan)
    hi = np.full_like(lo, np.nan)
    cols_out = slot[:, None] * width + np.arange(width)[None, :]
    lo[rows[:, None], cols_out] = opens
    hi[rows[:, None], cols_out] = closes
    return merge_intervals(lo, hi)


def cut_in_regions(
    ve0_mps: np.ndarray,
    vo0_mps: np.ndarray,
    vy_mps: np.ndarray,
    params: CCParams = _DEFAULT,
    search: RegionSearch = _SEARCH,
) -> Regions:
    """Every interval of dx0 (m) at which the C&C driver collides in the cut-in, per
    (Ve0, Vo0, Vy) (m/s; checked as in the grid builders: Vo0 <= Ve0, 0 < Vy feasible)."""
    ve0, vo0, vy = (np.asarray(a, dtype=float).reshape(-1) for a in (ve0_mps, vo0_mps, vy_mps))
    regions = _aeb_regions if params.aeb else _driver_regions
    # in cache-sized chunks, as the evaluator (same result, faster)
    parts = [
        regions(ve0[i : i + CHUNK], vo0[i : i + CHUNK], vy[i : i + CHUNK], params, search)
        for i in range(0, max(ve0.size, 1), CHUNK)
    ]
    if len(parts) == 1:
        return parts[0]
    width = max(r.lo.shape[1] for r in parts)

    def padded(a: np.ndarray) -> np.ndarray:
        return np.pad(a, ((0, 0), (0, width - a.shape[1])), constant_values=np.nan)

    return Regions(
        np.concatenate([padded(r.lo) for r in parts]), np.concatenate([padded(r.hi) for r in parts])
    )
