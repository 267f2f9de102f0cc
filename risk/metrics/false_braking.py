"""False-positive braking: braking episodes of the ego stack with no hazard in ground truth.

A step brakes when the commanded acceleration is at or below ``-min_decel``; an episode is a
maximal run of braking steps. An episode is the AEB's when the AEB applied a deceleration in
it, else the ACC's (following or speed keeping). It is false when ground truth gives no reason
for it at any of its steps: braking that starts early for a hazard that then materialises, or
that holds on to standstill after one, is not false. Reasons: a finite ground-truth time to
collision with some actor (hiyari.risk.metrics.ground_truth, 10 s horizon by default), or to
an actor coming within its near-miss limit of the ego's sides (risk.metrics.clearance); for the
ACC also a real actor ahead in, or entering, the ego's path within ``follow_thw`` of time
headway (following braking: a car cutting in slower than the ego and still moving sideways has
an infinite constant-velocity TTC, as it is predicted to cross the ego's path, yet braking to
open the gap behind it is right). The AEB, an emergency function, needs a finite TTC.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: s: the ACC's braking is following (not false) while a real actor is ahead in the ego's path
#: within this time headway (above the usual ACC time gaps of 1-2.5 s, so that settling onto
#: the gap counts too).
FOLLOW_THW = 3.0


@dataclass(frozen=True)
class FalseBraking:
    """False-positive braking of one source over a run: events, total duration (s) and the
    largest deceleration (m/s^2, positive; 0 without events)."""

    events: int = 0
    duration: float = 0.0
    peak_decel: float = 0.0


def false_braking(
    t: np.ndarray,
    accel: np.ndarray,
    ttc_true: np.ndarray,
    aeb_decel: np.ndarray,
    min_decel: float = 0.5,
    headway: np.ndarray | None = None,
    follow_thw: float = FOLLOW_THW,
    near_miss_time: np.ndarray | None = None,
) -> dict[str, FalseBraking]:
    """{"aeb": ..., "acc": ...} from per-step series: time ``t`` (s), commanded acceleration
    ``accel`` (m/s^2), ground-truth TTC ``ttc_true`` (s, inf: no hazard), the AEB's applied
    deceleration ``aeb_decel`` (m/s^2, positive; 0 when it does not brake) and the ground-truth
    time headway behind the nearest actor in the ego's path ``headway`` (s, inf: none; None:
    not known, only the TTC counts); ``near_miss_time`` (s, inf: none; None: not known): the
    ground-truth time until some actor comes within its near-miss limit of the ego's sides, a
    hazard like a finite TTC (risk.metrics.clearance.near_miss_time).

    Each step lasts until the next one (the last one as long as its predecessor)."""
    t = np.asarray(t, float)
    accel = np.asarray(accel, float)
    n = len(t)
    if n == 0:
        return {"aeb": FalseBraking(), "acc": FalseBraking()}
    dt = np.diff(t, append=t[-1] + (t[-1] - t[-2] if n > 1 else 0.0))
    brake = accel <= -min_decel
    start = brake & ~np.concatenate([[False], brake[:-1]])
    episode = np.cumsum(start) - 1  # episode index per braking step
    k = int(start.sum())
    finite = np.isfinite(np.asarray(ttc_true, float))
    if near_miss_time is not None and len(near_miss_time) == n:
        finite |= np.isfinite(np.asarray(near_miss_time, float))
    hazard = np.bincount(episode[brake], finite[brake], k) > 0
    near = np.zeros(n, bool) if headway is None else np.asarray(headway, float) < follow_thw
    following = np.bincount(episode[brake], near[brake], k) > 0
    by_aeb = np.bincount(episode[brake], (np.asarray(aeb_decel, float) > 0)[brake], k) > 0
    length = np.bincount(episode[brake], dt[brake], k)
    peak = np.zeros(k)
    np.maximum.at(peak, episode[brake], -accel[brake])
    out = {}
    for name, hit in (("aeb", by_aeb & ~hazard), ("acc", ~by_aeb & ~hazard & ~following)):
        out[name] = FalseBraking(
            events=int(hit.sum()),
            duration=float(length[hit].sum()),
            peak_decel=float(peak[hit].max()) if hit.any() else 0.0,
        )
    return out


@dataclass(frozen=True)
class FalseActivationRule:
    """What counts as a false activation of the ego's emergency functions (SI).

    An activation step is one with an AEB stage (warning included) or a braking command
    harder than ``comfort_decel``; an activation is a maximal run of such steps, gaps shorter
    than ``join_gap`` bridged. It is false when at none of its steps a ground-truth actor is in
    conflict with the ego: every ground-truth TTC (hiyari.risk.metrics.ground_truth.
    time_to_collision, footprints overlapping) above ``conflict_ttc``, and no actor coming
    within its near-miss limit of the ego's sides sooner than that (hiyari.risk.metrics.
    clearance.near_miss_time: a pass that close is a hazard braking answers). docs/models.md §4, "False
    activations".
    """

    #: m/s^2: the ACC's comfort limit (ACCConfig.max_decel): only the AEB brakes harder.
    comfort_decel: float = 3.0
    #: s: ground truth is in conflict while some actor's TTC is at or below this. 1.5 times
    #: the AEB's warning threshold (2.6 s): a stage the sensors raise a little early for a
    #: real threat, or for one a little farther than the stack estimates, is not false.
    conflict_ttc: float = 4.0
    #: s: activation steps less than this apart are one activation (0: every gap splits). The AEB applies the brake a
    #: stage commands after its actuation delay (0.2 s by default) and holds it to standstill:
    #: a stage that drops for a step or two before its braking starts is still the same event
    #: (two were counted for one in an R157 cut-in, issue #30). Above the default delay by a
    #: step of 0.05 s; a stack with a longer delay (0.8 s, the DIVP car) needs a longer gap.
    join_gap: float = 0.25


def false_activations(
    t: np.ndarray,
    accel: np.ndarray,
    aeb_stage: np.ndarray,
    ttc_true: np.ndarray,
    rule: FalseActivationRule = FalseActivationRule(),
    near_miss_time: np.ndarray | None = None,
) -> tuple[int, float]:
    """(count, first time s or nan) of false activations (:class:`FalseActivationRule`) from
    per-step series: time ``t`` (s), commanded acceleration ``accel`` (m/s^2), AEB stage
    decided (int, 0: off), the smallest ground-truth TTC over all actors ``ttc_true`` (s,
    inf: none) and the ground-truth time until some actor comes within its near-miss limit of
    the ego's sides ``near_miss_time`` (s, inf: none; None: not recorded)."""
    t = np.asarray(t, float)
    n = len(t)
    if n == 0:
        return 0, float("nan")
    stage = np.asarray(aeb_stage if len(aeb_stage) == n else np.zeros(n), float)
    active = (stage > 0) | (np.asarray(accel, float) < -rule.comfort_decel)
    if not active.any():
        return 0, float("nan")
    steps = np.flatnonzero(active)
    # a new activation starts at the first active step and after every run of inactive steps
    # whose active neighbours are join_gap or more apart
    gap = (np.diff(steps) > 1) & (t[steps[1:]] - t[steps[:-1]] >= rule.join_gap - 1e-9)
    new = np.concatenate([[True], gap])
    episode = np.cumsum(new) - 1
    k = int(new.sum())
    soonest = np.asarray(ttc_true, float)
    if near_miss_time is not None and len(near_miss_time) == n:
        soonest = np.minimum(soonest, np.asarray(near_miss_time, float))
    conflict = soonest[steps] <= rule.conflict_ttc
    justified = np.bincount(episode, conflict, k) > 0
    false = ~justified
    if not false.any():
        return 0, float("nan")
    return int(false.sum()), float(t[steps[new]][false][0])
