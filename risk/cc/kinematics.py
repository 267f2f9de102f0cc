"""Exact longitudinal kinematics of piecewise-constant-jerk motions, vectorised over scenarios.

Every motion in the C&C scenarios is piecewise polynomial in time: constant speed, linear
deceleration ramps, held deceleration, standstill. A :class:`Motion` stores N such motions as
(N, K) arrays of segment start times and the state at each start, so positions at any time
follow in closed form. The gap between two vehicles is then a piecewise cubic
(:class:`PiecewiseCubic`) whose minimum and first zero crossing are found from the roots of
its derivative: no time stepping, one pass of array arithmetic per segment.

Times in s from the start of the scenario, positions in m along the road, speeds in m/s,
accelerations in m/s² (negative = braking), jerks in m/s³.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_BISECTION_STEPS = 52


def _flat_index(shape: tuple[int, int], idx: np.ndarray) -> np.ndarray:
    """Indices into ``arr.ravel()`` of ``arr[i, idx[i, ...]]`` for an (N, K) array."""
    base = np.arange(shape[0]) * shape[1]
    return idx + base.reshape((-1,) + (1,) * (idx.ndim - 1))


def _gather(arr: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """``arr[i, idx[i, ...]]`` row by row (faster than take_along_axis for small K)."""
    return arr.ravel()[_flat_index(arr.shape, idx)]


def _poly(
    c0: np.ndarray, c1: np.ndarray, c2: np.ndarray, c3: np.ndarray, s: np.ndarray
) -> np.ndarray:
    return c0 + s * (c1 + s * (c2 + s * c3))


@dataclass(frozen=True)
class Motion:
    """N longitudinal motions, each K segments of constant jerk.

    ``t``: (N, K) segment start times, non-decreasing along K, ``t[:, 0] == 0``; ``inf`` marks
    a segment never reached. ``x``, ``v``, ``a``: position, speed, acceleration at each
    segment start; ``j``: jerk inside the segment. The last segment never ends.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    j: np.ndarray

    def state_at(self, tq: np.ndarray) -> tuple[np.ndarray, ...]:
        """Position, speed, acceleration and jerk at times ``tq`` (shape (N,) or (N, Q))."""
        tq = np.asarray(tq, dtype=float)
        flat = tq.ndim == 1
        tq2 = tq[:, None] if flat else tq
        idx = np.sum(self.t[:, None, :] <= tq2[:, :, None], axis=2) - 1
        flat_idx = _flat_index(self.t.shape, np.maximum(idx, 0))
        s = tq2 - self.t.ravel()[flat_idx]
        x0, v0, a0, j = (arr.ravel()[flat_idx] for arr in (self.x, self.v, self.a, self.j))
        with np.errstate(invalid="ignore"):
            x = x0 + s * (v0 + s * (a0 / 2 + s * j / 6))
            v = v0 + s * (a0 + s * j / 2)
            a = a0 + s * j
        out = (x, v, a, j)
        return tuple(o[:, 0] for o in out) if flat else out

    def state_in_segment(self, idx: np.ndarray, tq: np.ndarray) -> tuple[np.ndarray, ...]:
        """Position, speed, acceleration and jerk at times ``tq`` (N, Q) continuing segment
        ``idx`` (N, Q) of each row."""
        flat_idx = _flat_index(self.t.shape, idx)
        t0 = self.t.ravel()[flat_idx]
        s = np.where(np.isfinite(t0), tq - t0, 0.0)
        x0, v0, a0, j = (arr.ravel()[flat_idx] for arr in (self.x, self.v, self.a, self.j))
        x = x0 + s * (v0 + s * (a0 / 2 + s * j / 6))
        v = v0 + s * (a0 + s * j / 2)
        return x, v, a0 + s * j, j

    def rows(self, index: np.ndarray) -> Motion:
        """The motions of the given rows."""
        return Motion(*(arr[index] for arr in (self.t, self.x, self.v, self.a, self.j)))

    def shifted(self, dx: np.ndarray) -> Motion:
        """The same motions moved ``dx`` (N,) metres forward."""
        return Motion(self.t, self.x + np.asarray(dx, dtype=float)[:, None], self.v, self.a, self.j)

    @classmethod
    def constant_speed(cls, v: np.ndarray, x0: np.ndarray | float = 0.0) -> Motion:
        """Constant speed ``v`` from position ``x0``."""
        v = np.asarray(v, dtype=float)[:, None]
        zeros = np.zeros_like(v)
        return cls(
            t=zeros,
            x=zeros + x0 if np.isscalar(x0) else np.asarray(x0)[:, None],
            v=v,
            a=zeros,
            j=zeros,
        )

    @classmethod
    def step_deceleration(cls, v0: np.ndarray, decel: np.ndarray) -> Motion:
        """Deceleration ``decel`` (m/s², > 0) as a step at t = 0, held to standstill."""
        v0 = np.asarray(v0, dtype=float)
        decel = np.asarray(decel, dtype=float)
        with np.errstate(divide="ignore"):
            t_stop = np.where(decel > 0, v0 / decel, np.inf)
        x_stop = np.where(np.isfinite(t_stop), v0 * t_stop / 2, 0.0)
        zeros = np.zeros_like(v0)
        return cls(
            t=np.stack([zeros, t_stop], axis=1),
            x=np.stack([zeros, x_stop], axis=1),
            v=np.stack([v0, zeros], axis=1),
            a=np.stack([-decel, zeros], axis=1),
            j=np.zeros((v0.size, 2)),
        )

    @classmethod
    def braking(
        cls, v0: np.ndarray, knot_t: np.ndarray, knot_d: np.ndarray, v_end: np.ndarray
    ) -> Motion:
        """Constant speed ``v0``, then braking until the speed falls to ``v_end``, then ``v_end``.

        The deceleration (m/s², >= 0) is 0 before ``knot_t[:, 0]``, linear between knots
        (``knot_t``, ``knot_d``: (N, M), times non-decreasing, ``inf`` = never), and held at
        ``knot_d[:, -1]`` after the last knot. A motion that starts at or below ``v_end``
        never brakes.
        """
        v0 = np.asarray(v0, dtype=float)
        v_end = np.asarray(v_end, dtype=float)
        n, m = knot_t.shape
        zeros = np.zeros((n, 1))
        starts = np.concatenate([zeros, knot_t], axis=1)  # (N, M + 1)
        d_start = np.concatenate([zeros, knot_d], axis=1)
        d_end = np.concatenate([zeros, knot_d[:, 1:], knot_d[:, -1:]], axis=1)
        with np.errstate(invalid="ignore"):
            length = np.concatenate([np.diff(starts, axis=1), np.full((n, 1), np.inf)], axis=1)
            ramp = (length > 0) & np.isfinite(length)
            jerk = np.where(ramp, -(d_end - d_start) / np.where(ramp, length, 1.0), 0.0)
        k_total = m + 1
        xs = np.zeros((n, k_total))
        vs = np.zeros((n, k_total))
        vs[:, 0] = v0
        moving = v0 > v_end
        t_stop = np.where(moving, np.inf, 0.0)
        x_stop = np.zeros(n)
        stop_seg = np.full(n, -1)
        for k in range(k_total):
            a_k, j_k, L = -d_start[:, k], jerk[:, k], length[:, k]
            reached = np.isfinite(starts[:, k]) & np.isinf(t_stop)
            # smallest s >= 0 with v_k + a_k s + j_k s^2 / 2 = v_end (stable quadratic form)
            c = vs[:, k] - v_end
            with np.errstate(invalid="ignore", divide="ignore"):
                disc = a_k * a_k - 2.0 * j_k * c
                s_root = np.where(
                    disc >= 0, 2.0 * c / (-a_k + np.sqrt(np.maximum(disc, 0.0))), np.inf
                )
            s_root = np.where(np.isfinite(s_root) & (s_root >= 0), s_root, np.inf)
            hit = reached & (s_root <= L)
            with np.errstate(invalid="ignore"):
                x_hit = xs[:, k] + s_root * (vs[:, k] + s_root * (a_k / 2 + s_root * j_k / 6))
            t_stop = np.where(hit, starts[:, k] + s_root, t_stop)
            x_stop = np.where(hit, x_hit, x_stop)
            stop_seg = np.where(hit, k, stop_seg)
            if k + 1 < k_total:
                finite = np.isfinite(L)
                Lf = np.where(finite, L, 0.0)
                xs[:, k + 1] = np.where(
                    finite, xs[:, k] + Lf * (vs[:, k] + Lf * (a_k / 2 + Lf * j_k / 6)), 0.0
                )
                vs[:, k + 1] = np.where(finite, vs[:, k] + Lf * (a_k + Lf * j_k / 2), 0.0)
        v_after = np.minimum(v0, v_end)
        seg = np.arange(k_total)[None, :]
        after_stop = (stop_seg[:, None] >= 0) & (seg > stop_seg[:, None])
        after_stop |= ~moving[:, None] & (seg > 0)
        # segments the stop cut short collapse onto the stop: start and state both at it
        t_all = np.where(after_stop, t_stop[:, None], starts)
        x_all = np.where(after_stop, x_stop[:, None], xs)
        v_all = np.where(after_stop, v_after[:, None], vs)
        a_all = np.where(after_stop, 0.0, -d_start)
        j_all = np.where(after_stop, 0.0, jerk)
        return cls(
            t=np.concatenate([t_all, t_stop[:, None]], axis=1),
            x=np.concatenate([x_all, x_stop[:, None]], axis=1),
            v=np.concatenate([v_all, v_after[:, None]], axis=1),
            a=np.concatenate([a_all, zeros], axis=1),
            j=np.concatenate([j_all, zeros], axis=1),
        )


def ramp_knots(onset: np.ndarray, ramp_time: float, peak: float) -> tuple[np.ndarray, ...]:
    """Knots of a linear ramp from 0 at ``onset`` to ``peak`` (m/s²) ``ramp_time`` later."""
    onset = np.asarray(onset, dtype=float)
    t = np.stack([onset, onset + ramp_time], axis=1)
    d = np.stack([np.zeros_like(onset), np.full_like(onset, peak)], axis=1)
    return t, d


def profile_value(knot_t: np.ndarray, knot_d: np.ndarray, tq: np.ndarray) -> np.ndarray:
    """A deceleration profile (as in :meth:`Motion.braking`) at times ``tq`` (N, Q)."""
    out = np.zeros_like(tq)
    m = knot_t.shape[1]
    for i in range(m):
        t_a, d_a = knot_t[:, i : i + 1], knot_d[:, i : i + 1]
        if i + 1 < m:
            t_b, d_b = knot_t[:, i + 1 : i + 2], knot_d[:, i + 1 : i + 2]
            with np.errstate(invalid="ignore", divide="ignore"):
                seg = d_a + (tq - t_a) * (d_b - d_a) / (t_b - t_a)
            out = np.where((tq >= t_a) & (tq < t_b), seg, out)
        else:
            out = np.where(tq >= t_a, d_a, out)
    return out


def max_of_profiles(
    t1: np.ndarray, d1: np.ndarray, t2: np.ndarray, d2: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Knots of the pointwise maximum of two continuous piecewise-linear deceleration profiles.

    Each profile is 0 before its first knot (where it must start at 0), linear between knots
    and held after the last. The result has a knot at every input knot and at every crossing
    of the two profiles, so it is exact. ``inf`` knots (never reached) are allowed.
    """
    knots = np.sort(np.concatenate([t1, t2], axis=1), axis=1)
    lo, hi = knots[:, :-1], knots[:, 1:]
    both = np.isfinite(lo) & np.isfinite(hi)
    lo_q, hi_q = np.where(both, lo, 0.0), np.where(both, hi, 0.0)
    diff_lo = profile_value(t1, d1, lo_q) - profile_value(t2, d2, lo_q)
    diff_hi = profile_value(t1, d1, hi_q) - profile_value(t2, d2, hi_q)
    crossing = both & (diff_lo * diff_hi < 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        t_cross = lo + (hi - lo) * diff_lo / (diff_lo - diff_hi)
    extra = np.where(crossing, t_cross, lo)
    all_t = np.sort(np.concatenate([knots, extra], axis=1), axis=1)
    finite = np.isfinite(all_t)
    tq = np.where(finite, all_t, 0.0)
    all_d = np.maximum(profile_value(t1, d1, tq), profile_value(t2, d2, tq))
    last = np.take_along_axis(all_d, _last_finite(all_t), axis=1)
    return all_t, np.where(finite, all_d, last)


def _last_finite(t: np.ndarray) -> np.ndarray:
    count = np.sum(np.isfinite(t), axis=1, keepdims=True)
    return np.broadcast_to(np.maximum(count - 1, 0), t.shape)


@dataclass(frozen=True)
class PiecewiseCubic:
    """N piecewise-cubic functions of time: on segment k, p = c0 + c1 s + c2 s² + c3 s³ with
    s = t - t[:, k]. Segments starting at ``inf`` are never reached; the last never ends.
    All arrays are (N, K)."""

    t: np.ndarray
    c0: np.ndarray
    c1: np.ndarray
    c2: np.ndarray
    c3: np.ndarray

    @classmethod
    def gap(cls, offset: np.ndarray, lead: Motion, follower: Motion) -> PiecewiseCubic:
        """Gap ``offset + x_lead(t) - x_follower(t)`` as a piecewise cubic (exact)."""
        if lead.t.shape[1] == 1:
            # one segment from t = 0: the follower's segments are the gap's, and its stored
            # states are already the states at their starts
            starts = follower.t
            finite = np.isfinite(starts)
            tq = np.where(finite, starts, 0.0)
            xf, vf, af, jf = follower.x, follower.v, follower.a, follower.j
            xl = lead.x + tq * (lead.v + tq * (lead.a / 2 + tq * lead.j / 6))
            vl = lead.v + tq * (lead.a + tq * lead.j / 2)
            al = lead.a + tq * lead.j
            jl = lead.j
        else:
            # merge the two knot lists; each motion's segment at a merged knot is the number
            # of its own knots up to there (a knot repeated within one motion keeps the
            # earlier segment's end: the left limit at a jump)
            both = np.concatenate([lead.t, follower.t], axis=1)
            order = np.argsort(both, axis=1, kind="stable")
            starts = np.take_along_axis(both, order, axis=1)
            finite = np.isfinite(starts)
            tq = np.where(finite, starts, 0.0)
            from_lead = order < lead.t.shape[1]
            idx_l = np.maximum(np.cumsum(from_lead, axis=1) - 1, 0)
            idx_f = np.maximum(np.cumsum(~from_lead, axis=1) - 1, 0)
            xl, vl, al, jl = lead.state_in_segment(idx_l, tq)
            xf, vf, af, jf = follower.state_in_segment(idx_f, tq)
        offset = np.asarray(offset, dtype=float)[:, None]
        return cls(
            t=starts,
            c0=np.where(finite, offset + xl - xf, 0.0),
            c1=np.where(finite, vl - vf, 0.0),
            c2=np.where(finite, (al - af) / 2, 0.0),
            c3=np.where(finite, (jl - jf) / 6, 0.0),
        )

    def rows(self, index: np.ndarray) -> PiecewiseCubic:
        """The functions of the given rows."""
        return PiecewiseCubic(*(arr[index] for arr in (self.t, self.c0, self.c1, self.c2, self.c3)))

    def _segment_of(self, tq: np.ndarray) -> tuple[np.ndarray, ...]:
        idx = np.maximum(np.sum(self.t <= tq[:, None], axis=1) - 1, 0)
        flat_idx = _flat_index(self.t.shape, idx)
        s = tq - self.t.ravel()[flat_idx]
        return (s, *(c.ravel()[flat_idx] for c in (self.c0, self.c1, self.c2, self.c3)))

    def value(self, tq: np.ndarray) -> np.ndarray:
        """p(tq) for tq of shape (N,) (finite)."""
        s, c0, c1, c2, c3 = self._segment_of(tq)
        return _poly(c0, c1, c2, c3, s)

    def derivative_value(self, tq: np.ndarray) -> np.ndarray:
        """dp/dt at tq (N,)."""
        s, _, c1, c2, c3 = self._segment_of(tq)
        return c1 + s * (2 * c2 + s * 3 * c3)

    def shifted(self, delta: float) -> PiecewiseCubic:
        """p + delta."""
        return PiecewiseCubic(self.t, self.c0 + delta, self.c1, self.c2, self.c3)

    def plus_derivative(self, horizon: float) -> PiecewiseCubic:
        """p + horizon x dp/dt (for a gap: gap - horizon x closing speed)."""
        return PiecewiseCubic(
            self.t,
            self.c0 + horizon * self.c1,
            self.c1 + 2 * horizon * self.c2,
            self.c2 + 3 * horizon * self.c3,
            self.c3,
        )

    def _window(
        self, ts: np.ndarray, te: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per segment: local [s0, s1] of its part within [ts, te] (te None: no end), and
        whether it exists."""
        finite = np.isfinite(self.t)
        t0 = np.where(finite, self.t, 0.0)
        lengths = np.empty_like(t0)
        lengths[:, :-1] = np.diff(t0, axis=1)
        # a segment followed only by never-reached ones lasts for ever
        lengths[:, :-1] = np.where(finite[:, 1:], lengths[:, :-1], np.inf)
        lengths[:, -1] = np.inf
        s0 = np.maximum(ts[:, None] - t0, 0.0)
        active = finite & ((t0 + lengths > ts[:, None]) | (t0 >= ts[:, None]))
        if te is None:
            return s0, lengths, active
        s1 = np.minimum(lengths, te[:, None] - t0)
        # a segment starting at te is excluded: at a jump the window takes the left limit
        starts_before = (t0 < te[:, None]) | (t0 <= ts[:, None])
        return s0, s1, active & (s1 >= s0) & starts_before

    def _critical_points(self) -> tuple[np.ndarray, np.ndarray]:
        """Both roots of dp/ds per segment (nan where absent)."""
        qa, qb, qc = 3 * self.c3, 2 * self.c2, self.c1
        with np.errstate(invalid="ignore", divide="ignore"):
            disc = qb * qb - 4 * qa * qc
            q = -0.5 * (qb + np.copysign(np.sqrt(disc), qb))
            cubic = qa != 0
            r1 = np.where(cubic, q / qa, -qc / qb)
            r2 = np.where(cubic, qc / q, np.nan)
        return r1, r2

    def _segment_minima(self, ts: np.ndarray, te: np.ndarray | None = None) -> np.ndarray:
        """(N, K) minimum of each segment over its part within [ts, te] (+inf if none)."""
        s0, s1, active = self._window(ts, te)
        c0, c1, c2, c3 = self.c0, self.c1, self.c2, self.c3
        s1_finite = np.isfinite(s1)
        best = np.minimum(
            _poly(c0, c1, c2, c3, s0), _poly(c0, c1, c2, c3, np.where(s1_finite, s1, s0))
        )
        if (c2 != 0).any() or (c3 != 0).any():
            for r in self._critical_points():
                inside = (r > s0) & (r < s1)  # false for nan
                best = np.where(inside, np.minimum(best, _poly(c0, c1, c2, c3, r)), best)
        lead = np.where(c3 != 0, c3, np.where(c2 != 0, c2, c1))
        best = np.where(~s1_finite & (lead < 0), -np.inf, best)
        return np.where(active, best, np.inf)

    def minimum_after(self, ts: np.ndarray) -> np.ndarray:
        """min over t >= ts of p(t), (N,); -inf if p decreases without bound."""
        with np.errstate(invalid="ignore"):
            return self._segment_minima(np.asarray(ts, dtype=float)).min(axis=1)

    def minimum_between(self, ts: np.ndarray, te: np.ndarray) -> np.ndarray:
        """inf over ts <= t < te of p(t), closed at te by the left limit, (N,); +inf where
        te < ts. A jump at te is not part of the window."""
        ts, te = np.asarray(ts, dtype=float), np.asarray(te, dtype=float)
        with np.errstate(invalid="ignore"):
            return self._segment_minima(ts, te).min(axis=1)

    def first_negative(self, ts: np.ndarray) -> np.ndarray:
        """First time t >= ts at which p becomes negative (the root where it crosses 0), (N,);
        ``ts`` itself where p(ts) < 0 already, ``inf`` where p stays >= 0."""
        ts = np.asarray(ts, dtype=float)
        out = np.full(ts.size, np.inf)
        at_start = self.value(ts) < 0
        out[at_start] = ts[at_start]
        with np.errstate(invalid="ignore"):
            neg = self._segment_minima(ts) < 0
        rows = np.flatnonzero(neg.any(axis=1) & ~at_start)
        if rows.size == 0:
            return out
        sub = self.rows(rows)
        k = np.argmax(neg[rows], axis=1)[:, None]
        s0, s1, _ = sub._window(ts[rows])
        s0, s1 = _gather(s0, k)[:, 0], _gather(s1, k)[:, 0]
        c0, c1, c2, c3 = (_gather(c, k)[:, 0] for c in (sub.c0, sub.c1, sub.c2, sub.c3))
        r1, r2 = (_gather(r, k)[:, 0] for r in sub._critical_points())
        # an unbounded last segment: push the upper end out until p is negative there
        hi_end = np.where(np.isfinite(s1), s1, s0 + 1.0)
        for _ in range(80):
            grow = ~np.isfinite(s1) & (_poly(c0, c1, c2, c3, hi_end) >= 0)
            if not grow.any():
                break
            hi_end = np.where(grow, s0 + 2 * (hi_end - s0), hi_end)
        # between critical points p is monotone: bracket the first piece that ends below 0
        cuts = [s0]
        for r in (r1, r2):
            cuts.append(np.where((r > s0) & (r < hi_end), r, s0))
        cuts.append(hi_end)
        cuts = np.sort(np.stack(cuts, axis=1), axis=1)
        values = _poly(c0[:, None], c1[:, None], c2[:, None], c3[:, None], cuts)
        piece = np.argmax(values[:, 1:] < 0, axis=1)[:, None]
        lo = _gather(cuts, piece)[:, 0]
        hi = _gather(cuts, piece + 1)[:, 0]
        for _ in range(_BISECTION_STEPS):
            mid = 0.5 * (lo + hi)
            below = _poly(c0, c1, c2, c3, mid) < 0
            hi = np.where(below, mid, hi)
            lo = np.where(below, lo, mid)
        out[rows] = _gather(sub.t, k)[:, 0] + hi
        return out
