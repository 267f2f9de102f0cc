"""The C&C reference driver of the closed loop follows the model's ``above_ttc`` convention:
by default it reacts at the danger judgement of a car cutting in whatever its TTC; with
"wait" not before the car is within ``ttc_brake_s``. Worked by hand on a cut-in 100 m ahead."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.bridge.loop.drivers.cc_driver import CCReferencePlanner
from hiyari.kinematics import Pose
from hiyari.risk.cc.model import CCParams
from hiyari.sensors.outputs import ObjectList

DV = 15.0  # m/s closing speed
VY = 1.0  # m/s toward the ego lane


def _cut_in(t: float) -> ObjectList:
    """A 5.3 m x 1.9 m car starting in the left lane (y = 3.5 m) with its rear 100 m ahead of
    the ego's front (ego 4.8 m long), in the ego frame."""
    x = 100.0 + 2.4 + 2.65 - DV * t
    return ObjectList(
        t, "fusion", np.eye(4), np.array([1]), np.array([0], np.int8),
        np.array([[x, 3.5 - VY * t, 0.0]]), np.array([[-DV, -VY, 0.0]]),
        np.array([[5.3, 1.9, 1.5]]), np.ones(1), np.array(["car"], dtype=object),
    )  # fmt: skip


def _first_braking(params: CCParams) -> tuple[float, CCReferencePlanner]:
    planner = CCReferencePlanner(params)
    ego = Pose(0.0, 0.0, speed=25.0)
    for k in range(100):
        t = round(0.1 * k, 10)
        if planner.plan(_cut_in(t), ego, t).accel < 0:
            return t, planner
    raise AssertionError("never braked")


def test_default_reacts_at_danger_judgement():
    """The car's side comes within 0.375 m of the ego's corridor (|y| <= 1.75 + 0.95 - 0.375
    = 2.325 m) at t = 1.175 s: judged at the 1.2 s step, danger 0.4 s later, braking force
    0.75 s after that: first braking at the 2.4 s step (TTC then 5.7 s)."""
    t, planner = _first_braking(CCParams())
    assert planner.reaction_time() == pytest.approx(1.6)
    assert t == pytest.approx(2.4)


def test_wait_reacts_when_ttc_falls_to_two_seconds():
    """The gap 100 - 15 t falls below 2 s x 15 m/s = 30 m after 4.667 s: critical at the
    4.7 s step, braking force 0.75 s later: first braking at the 5.5 s step."""
    t, planner = _first_braking(CCParams(above_ttc="wait"))
    assert planner.reaction_time() == pytest.approx(4.7)
    assert t == pytest.approx(5.5)
