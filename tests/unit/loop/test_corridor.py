"""The AEB's corridor follows the road's curvature (issue 30, item 5): a car keeping the
adjacent lane of a curve is no threat, a car ahead in the ego's lane still is."""

from __future__ import annotations

import math

import numpy as np

from hiyari.bridge.loop.stack.aeb import AEBConfig, AEBPlanner, time_to_collision
from hiyari.bridge.loop.stack.corridor import PathCurvature
from hiyari.kinematics import Pose
from hiyari.sensors.outputs import ObjectList

RADIUS = 300.0  # m, a left curve (ALKS 4_1_3's road bends this much)
SPEED = 16.67  # m/s, everybody
LANE = 3.5
SLOWER = 12.0  # m/s, a car the ego overtakes


def _on_arc(s: float, d: float) -> tuple[float, float, float]:
    """World x, y, heading of a point ``s`` m along a left arc of RADIUS through the origin
    (heading +x there), ``d`` m to its left."""
    phi = s / RADIUS
    r = RADIUS - d
    return r * math.sin(phi), RADIUS - r * math.cos(phi), phi


def _ego(s: float) -> Pose:
    x, y, h = _on_arc(s, 0.0)
    return Pose(x, y, 0.0, h, SPEED, 0.0, 4.8, 1.9)


def _track(ego: Pose, s: float, d: float, speed: float = SPEED) -> ObjectList:
    """A car at (s, d) on the curve at ``speed`` along it, in the ego's frame (relative
    velocity, as the fusion gives it)."""
    x, y, h = _on_arc(s, d)
    pos = ego.world_to_vehicle(np.array([x, y]))
    vel = ego.world_to_vehicle_vec(speed * np.array([math.cos(h), math.sin(h)]) - ego.velocity)
    return ObjectList(
        0.0, "fusion", np.eye(4), np.array([1]), np.array([0], np.int8),
        np.array([[*pos, 0.0]]), np.array([[*vel, 0.0]]), np.array([[5.3, 1.9, 1.5]]),
        np.ones(1), np.array(["car"], dtype=object),
    )  # fmt: skip


def _curvature_after(metres: float) -> float:
    path = PathCurvature()
    k = 0.0
    for s in np.arange(0.0, metres, SPEED * 0.05):
        k = path.update(_ego(float(s)))
    return k


def test_path_curvature_is_the_road_curvature():
    assert _curvature_after(60.0) == np.float64(_curvature_after(60.0))  # same inputs, same value
    assert abs(_curvature_after(60.0) - 1.0 / RADIUS) < 1e-4
    assert _curvature_after(2.0) == 0.0  # too little travelled: straight


def test_car_in_the_adjacent_lane_of_a_curve_is_no_threat():
    ego, cfg, straight = _ego(100.0), AEBConfig(), []
    for gap in np.arange(5.0, 60.0, 1.0):
        right = _track(ego, 100.0 + gap, -LANE, SLOWER)  # the outer lane of a left curve
        assert time_to_collision(right, ego, cfg, 1.0 / RADIUS)[0] == np.inf
        straight.append(float(time_to_collision(right, ego, cfg)[0]))
    assert min(straight) < cfg.warning_ttc  # the straight prediction cuts through it


def test_car_ahead_in_the_ego_lane_of_a_curve_is_still_a_threat():
    ego = _ego(100.0)
    ahead = _track(ego, 100.0 + 30.0, 0.0)
    standing = np.array([[-SPEED, 0.0, 0.0]])  # relative to the ego: minus its velocity
    closing = ObjectList(**{**ahead.__dict__, "velocity": standing})
    ttc = float(time_to_collision(closing, ego, AEBConfig(), 1.0 / RADIUS)[0])
    assert abs(ttc - (30.0 - 0.5 * (5.3 + 4.8)) / SPEED) < 0.05  # a standing car, along the arc


def test_planner_raises_no_stage_for_the_adjacent_lane_of_a_curve():
    straight, planner = [], AEBPlanner()
    for k in range(300):  # 15 s: overtaking a slower car, from 60 m behind it to beside it
        t = 0.05 * k
        ego = _ego(SPEED * t)
        track = _track(ego, 60.0 + SLOWER * t, -LANE, SLOWER)
        assert int(planner.plan(track, ego, t).aeb_stage) == 0
        straight.append(float(time_to_collision(track, ego, planner.aeb)[0]))
    assert min(straight) < AEBConfig().warning_ttc  # a straight corridor would have warned


def test_a_long_truck_beside_the_ego_heads_along_the_lane_at_its_rear_axle():
    """ALKS 4_1_3: an 18.75 m truck in the outer lane of a right curve (radius 240 m), its box
    centre 9 m ahead of the ego's, heading along the lane at its rear axle (3.75 m from its
    rear): the straight corridor saw it cut in (TTC 2-3 s, AEB warnings from 64.8 s)."""
    radius, length = -240.0, 18.75
    k = 1.0 / radius
    ego = Pose(0.0, 0.0, 0.0, 0.0, SPEED, 0.0, 4.8, 1.9)
    axle_s = 9.0 - 0.5 * length + 0.2 * length  # along the arc, from the ego's centre
    heading = axle_s * k  # the lane's tangent at the truck's rear axle (right curve: < 0)
    d = 3.0  # its centre's offset to the left of the ego's path, m
    centre = np.array([9.0, d - 0.5 * k * 81.0])  # on the outer arc, ego frame
    r = SPEED * (radius - d) / radius  # same angular speed as the ego: it keeps beside it
    vel = r * np.array([math.cos(heading), math.sin(heading)]) - [SPEED, 0.0]
    truck = ObjectList(
        0.0, "fusion", np.eye(4), np.array([1]), np.array([1], np.int8),
        np.array([[*centre, 0.0]]), np.array([[*vel, 0.0]]), np.array([[length, 2.5, 4.0]]),
        np.ones(1), np.array(["truck"], dtype=object),
    )  # fmt: skip
    cfg = AEBConfig()
    assert float(time_to_collision(truck, ego, cfg)[0]) < 3.0  # straight: cutting in
    assert time_to_collision(truck, ego, cfg, k)[0] == np.inf
