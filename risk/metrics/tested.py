"""RunTested or not: whether a run reached the critical event it was built to test.

A scenario tests the ego's answer to a disturbance (a car cutting in, a lead braking, a child
stepping out). If the ego already braked hard, stopped or left its lane before that
disturbance started, the run did not test it: whatever follows (no collision included) says
nothing about the answer, and such a run is never counted as passed (docs/models.md §4,
"RunTested or not").

The disturbance starts at the first start of an Event that acts on an actor other than the
ego (hiyari.bridge.loop.hooks.EngineHooks): the manoeuvre start of a TOML preset (its events
are on the other actors at script time 0), the first such Event of an OpenSCENARIO
storyboard. A scenario without one (a stationary target, free driving) has its hazard from
the start: its runs are tested by this rule (an early stop there is a false activation, which
hiyari.risk.metrics.false_braking counts).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RunTestedRule:
    """The thresholds of the rule (SI)."""

    #: m/s^2: braking harder than this before the disturbance makes the run untested. The
    #: ACC's comfort limit (ACCConfig.max_decel, 3 m/s^2; ISO 15622 keeps an ACC's
    #: deceleration to a few m/s^2, 3.5 m/s^2 at higher speeds): only an emergency function
    #: brakes harder.
    brake_decel: float = 3.0
    #: m/s: the ego counts as stopped below this speed (after having moved faster).
    stopped_speed: float = 0.1


#: Causes of an untested run, in the order they are reported when several hold at once.
BRAKED, STOPPED, LEFT_LANE, NOT_REACHED = "braked", "stopped", "left its lane", "not reached"


@dataclass(frozen=True)
class RunTested:
    """``tested``; when not, ``cause`` (one of BRAKED, STOPPED, LEFT_LANE, NOT_REACHED) and
    ``time`` (s) at which it first held, and a sentence saying so (``reason``)."""

    tested: bool = True
    cause: str = ""
    time: float = float("nan")
    reason: str = ""


def run_tested(
    t: np.ndarray,
    speed: np.ndarray,
    accel_cmd: np.ndarray,
    disturbance_time: float,
    has_disturbance: bool,
    lane_left_time: float = float("nan"),
    rule: RunTestedRule = RunTestedRule(),
) -> RunTested:
    """Whether a run tested its disturbance, from its per-step series: time ``t`` (s), ego
    ``speed`` (m/s), commanded acceleration ``accel_cmd`` (m/s^2), the time the disturbance
    started ``disturbance_time`` (s; nan: not reached), whether the scenario has one
    (``has_disturbance``; False: always tested) and the time the ego first left its lane
    ``lane_left_time`` (s; nan: never)."""
    if not has_disturbance:
        return RunTested()
    t = np.asarray(t, float)
    speed = np.asarray(speed, float)
    accel_cmd = np.asarray(accel_cmd, float)
    reached = bool(np.isfinite(disturbance_time))
    before = t < disturbance_time if reached else np.ones(len(t), bool)
    moved = np.maximum.accumulate(speed >= rule.stopped_speed) if len(t) else before
    found = []
    for cause, hit in (
        (BRAKED, before & (accel_cmd < -rule.brake_decel)),
        (STOPPED, before & moved & (speed < rule.stopped_speed)),
    ):
        if hit.any():
            found.append((float(t[np.argmax(hit)]), cause))
    if np.isfinite(lane_left_time) and (not reached or lane_left_time < disturbance_time):
        found.append((float(lane_left_time), LEFT_LANE))
    if found:
        when, cause = min(found, key=lambda f: f[0])
        at = f"at {disturbance_time:.2f} s" if reached else "(never reached)"
        return RunTested(
            False, cause, when, f"{cause} at {when:.2f} s, before the disturbance {at}"
        )
    if not reached:
        return RunTested(False, NOT_REACHED, float("nan"), "the run ended before the disturbance")
    return RunTested()
