"""One false activation per event (issue 30, item 4): the AEB's actuation delay must not split
one event into two; braking for a pedestrian the ego is about to pass within the near-miss
limit is not false."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.risk.metrics.clearance import near_miss_time
from hiyari.risk.metrics.false_braking import FalseActivationRule, false_activations
from hiyari.traffic.actor_class import ActorClass

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


def _pass_geometry(side_gap: float, cls: int, ego_speed: float = 60 / 3.6) -> float:
    """Ground-truth near-miss time of the ALKS 4_2_2 pass: the ego (5 m x 2 m) at the origin
    heading +x, a standing actor (0.3 m x 0.5 m) 30 m ahead, ``side_gap`` m beside its right
    side."""
    xy = np.array([[0.0, 0.0], [30.0, -(1.0 + side_gap + 0.25)]])
    return near_miss_time(
        xy, np.zeros(2), np.array([ego_speed, 0.0]), np.array([5.0, 0.3]),
        np.array([2.0, 0.5]), np.array([ActorClass.CAR, cls]), 0,
    )  # fmt: skip


def test_a_road_user_about_to_be_passed_within_the_near_miss_limit_is_a_conflict():
    # ALKS 4_2_2 with sensors: full braking for the pedestrian standing in the ego's lane
    # 0.25 m beside the ego's path at 60 km/h. Contact TTC: none; the pass would be a near
    # miss (limit 0.5 + 0.08 x 16.67 = 1.83 m): braking answers it, it is not false.
    ped = int(ActorClass.PEDESTRIAN)
    gap_to_pedestrian = 30.0 - 0.15 - 2.5  # m, ego front to the pedestrian's rear
    assert _pass_geometry(0.25, ped) == pytest.approx(gap_to_pedestrian / (60 / 3.6))
    assert _pass_geometry(1.80, ped) < np.inf  # inside 1.83 m
    assert _pass_geometry(1.90, ped) == np.inf  # outside it
    # a vehicle: its own limit, 0.2 + 0.01 x 16.67 = 0.37 m
    assert _pass_geometry(0.25, int(ActorClass.CAR)) == pytest.approx(
        gap_to_pedestrian / (60 / 3.6)
    )
    assert _pass_geometry(0.40, int(ActorClass.CAR)) == np.inf
    assert _pass_geometry(0.25, ped, ego_speed=0.5) == np.inf  # nothing passed below 1 m/s
    n = len(T)
    stage = np.zeros(n, int)
    accel = np.zeros(n)
    stage[20:30] = 3
    accel[24:40] = -7.8
    ttc = np.full(n, np.inf)  # no contact in ground truth
    near = np.full(n, np.inf)
    assert false_activations(T, accel, stage, ttc, near_miss_time=near)[0] == 1
    near[20:40] = 1.6 - 0.05 * np.arange(20)  # the pass 1.6 s ahead and closing
    assert false_activations(T, accel, stage, ttc, near_miss_time=near)[0] == 0
