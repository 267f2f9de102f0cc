"""One false activation per event (issue 30, item 4): the AEB's actuation delay must not split
one event into two."""

from __future__ import annotations

import numpy as np

from hiyari.risk.metrics.false_braking import FalseActivationRule, false_activations

DT = 0.05
T = np.arange(0.0, 4.0, DT)


def test_a_stage_that_drops_before_its_delayed_brake_is_one_activation():
    # as the AEB planner does it: partial braking decided at 1.0 s for one step (the stack's
    # TTC then rises again), applied 0.2 s later and held to standstill at 0.4 g
    n = len(T)
    stage = np.zeros(n, int)
    accel = np.zeros(n)
    stage[20] = 2  # t = 1.00 s
    accel[24:40] = -0.4 * 9.81  # t = 1.20 .. 1.95 s: the brake, after the 0.2 s delay
    ttc = np.full(n, np.inf)  # nothing in conflict
    assert false_activations(T, accel, stage, ttc) == (1, T[20])
    # a second event 0.25 s after the first one's last step is one more (the gap is not bridged)
    stage[44] = 1  # t = 2.20 s
    assert false_activations(T, accel, stage, ttc)[0] == 2
    # the join follows the rule: with no gap bridged, the delayed brake is a second activation
    stage[44] = 0
    assert false_activations(T, accel, stage, ttc, FalseActivationRule(join_gap=0.0))[0] == 2


def test_a_joined_event_is_justified_by_a_conflict_in_either_part():
    n = len(T)
    stage = np.zeros(n, int)
    accel = np.zeros(n)
    stage[20] = 3
    accel[24:40] = -7.8
    ttc = np.full(n, np.inf)
    ttc[30] = 0.8  # the threat is real by the time the brake acts
    assert false_activations(T, accel, stage, ttc)[0] == 0
