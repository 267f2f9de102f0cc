"""Verdicts that can be trusted (issue 30): tested or not, false activations, near misses."""

from __future__ import annotations

import numpy as np

from hiyari.risk.metrics.clearance import NearMissRule, PassingClearances
from hiyari.risk.metrics.false_braking import FalseActivationRule, false_activations
from hiyari.risk.metrics.tested import BRAKED, LEFT_LANE, NOT_REACHED, STOPPED, run_tested
from hiyari.traffic.actor_class import ActorClass
from hiyari.units import kmh_to_mps

DT = 0.05
T = np.arange(0.0, 6.0, DT)  # the disturbance starts at 1.5 s (a preset's lead-in)
START = 1.5


def _braking_from(t0: float, decel: float, v0: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """Speed and commanded acceleration of an ego braking at ``decel`` from ``t0`` to a stop."""
    accel = np.where(T >= t0, -decel, 0.0)
    speed = np.maximum(v0 - decel * np.maximum(T - t0, 0.0), 0.0)
    return speed, np.where(speed > 0, accel, 0.0)


def test_braking_before_the_disturbance_is_not_tested():
    speed, accel = _braking_from(0.1, 7.8)  # full AEB at t = 0.1 s on a phantom
    r = run_tested(T, speed, accel, START, True)
    assert not r.tested and r.cause == BRAKED and abs(r.time - 0.1) < 1e-9
    assert "before the disturbance" in r.reason


def test_a_stop_before_the_disturbance_is_not_tested():
    speed = np.maximum(2.0 - 2.0 * T, 0.0)  # gentle braking (2 m/s^2) to a stop at 1 s
    r = run_tested(T, speed, -2.0 * (speed > 0), START, True)
    assert not r.tested and r.cause == STOPPED and abs(r.time - 1.0) <= DT


def test_leaving_the_lane_before_the_disturbance_is_not_tested():
    speed, accel = _braking_from(10.0, 0.0)
    assert run_tested(T, speed, accel, START, True, lane_left_time=0.8).cause == LEFT_LANE
    assert run_tested(T, speed, accel, START, True, lane_left_time=2.0).tested  # after: tested


def test_braking_for_the_disturbance_is_tested():
    speed, accel = _braking_from(START + 0.3, 7.8)  # hard, but an answer to it
    assert run_tested(T, speed, accel, START, True).tested
    # the ACC's comfort braking before it (3 m/s^2, not harder) leaves the run tested
    speed, accel = _braking_from(0.5, 3.0)
    assert run_tested(T, speed, accel, START, True).tested


def test_a_disturbance_never_reached_is_not_tested_and_none_means_tested():
    speed, accel = _braking_from(10.0, 0.0)
    assert run_tested(T, speed, accel, float("nan"), True).cause == NOT_REACHED
    speed, accel = _braking_from(0.1, 7.8)
    assert run_tested(T, speed, accel, float("nan"), False).tested  # hazard from the start


def test_false_activations_count_episodes_without_a_ground_truth_conflict():
    n = len(T)
    stage = np.zeros(n, int)
    accel = np.zeros(n)
    ttc = np.full(n, np.inf)
    stage[10:20] = 1  # a warning with nothing near: false
    stage[40:60], accel[45:60] = 3, -7.8  # full braking for nothing: false
    stage[80:100], ttc[90:100] = 2, 1.5  # braking for a real threat: justified
    accel[105:110] = -5.0  # braking harder than the ACC can, for nothing: false
    assert false_activations(T, accel, stage, ttc) == (3, T[10])
    # a conflict bound above the TTCs seen makes every episode with a finite one justified
    ttc[10:20] = 6.0
    assert false_activations(T, accel, stage, ttc, FalseActivationRule(conflict_ttc=7.0))[0] == 2
    assert false_activations(T, np.zeros(n), np.zeros(n, int), ttc)[0] == 0


def _pass(actor: ActorClass, lateral: float, speed: float) -> PassingClearances:
    """The ego (4.8 x 1.9 m) driving along x at ``speed`` past a standing ``actor`` whose
    near side is ``lateral`` m from the ego's side."""
    size = {ActorClass.PEDESTRIAN: (0.3, 0.5), ActorClass.CAR: (5.3, 1.9)}[actor]
    c = PassingClearances()
    for x in np.arange(-20.0, 20.0, speed * DT):
        xy = np.array([[x, 0.0], [0.0, -(0.95 + lateral + size[1] / 2)]])
        c.update(
            x, np.array(["ego", "other"], object), np.array([0, int(actor)]), xy,
            np.zeros(2), np.array([4.8, size[0]]), np.array([1.9, size[1]]), 0, speed,
        )  # fmt: skip
    return c


def test_a_pedestrian_passed_at_a_quarter_metre_at_60_kmh_is_a_near_miss():
    v = kmh_to_mps(60.0)
    close = _pass(ActorClass.PEDESTRIAN, 0.25, v)
    p = close.passes["other"]
    assert p.vru and abs(p.clearance - 0.25) < 1e-9 and p.near_miss
    assert [q.actor for q in close.near_misses()] == ["other"]
    assert close.near_misses(exclude="other") == []  # the one hit is a collision instead
    assert not _pass(ActorClass.PEDESTRIAN, 2.0, v).passes["other"].near_miss
    # the limit grows with speed: 1.0 m is fine crawling by, not at 60 km/h
    assert not _pass(ActorClass.PEDESTRIAN, 1.0, 2.0).passes["other"].near_miss
    assert _pass(ActorClass.PEDESTRIAN, 1.0, v).passes["other"].near_miss


def test_vehicle_limits_are_smaller_than_vru_limits():
    v = kmh_to_mps(100.0)
    assert not _pass(ActorClass.CAR, 1.0, v).passes["other"].near_miss  # adjacent lane
    assert _pass(ActorClass.CAR, 0.3, v).passes["other"].near_miss
    rule = NearMissRule()
    assert rule.limit(True, v) > rule.limit(False, v)
    assert PassingClearances().passes == {} and _pass(ActorClass.CAR, 1.0, 0.5).passes == {}
