"""The kinematics kernel against hand-computed geometry: frames, footprints, time to overlap,
gaps; and the ground-truth metrics built on it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiyari.kinematics import (
    Pose,
    box_corners,
    box_distance,
    box_entry_time,
    bumper_gap,
    disc_entry_time,
    footprint_corners,
    footprint_entry_time,
    footprint_extent,
    point_ahead,
    rectangle_point_distance,
    rotate,
    rounded_box_entry_time,
    slab_interval,
    unrotate,
    vehicle_to_world,
    world_to_vehicle,
    wrap_angle,
)
from hiyari.risk.metrics.ground_truth import TruthConfig, gap_to, time_to_collision

R2 = math.sqrt(2.0)


def test_pose_frames_by_hand():
    ego = Pose(10.0, 5.0, 1.0, math.pi / 2, speed=3.0)
    # 2 m ahead and 0.5 m left of a car heading north: 2 m north, 0.5 m west
    np.testing.assert_allclose(ego.vehicle_to_world([2.0, 0.5]), [9.5, 7.0], atol=1e-12)
    np.testing.assert_allclose(ego.world_to_vehicle([9.5, 7.0]), [2.0, 0.5], atol=1e-12)
    np.testing.assert_allclose(ego.vehicle_to_world([2.0, 0.5, 0.3]), [9.5, 7.0, 1.3], atol=1e-12)
    m = ego.to_world()
    np.testing.assert_allclose(m @ [2.0, 0.5, 0.3, 1.0], [9.5, 7.0, 1.3, 1.0], atol=1e-12)
    np.testing.assert_allclose(ego.velocity, [0.0, 3.0], atol=1e-12)
    # vectors turn but do not move
    np.testing.assert_allclose(ego.world_to_vehicle_vec([[0.0, 3.0]]), [[3.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(ego.vehicle_to_world_vec([[1.0, 0.0]]), [[0.0, 1.0]], atol=1e-12)


def test_array_transforms_broadcast_and_keep_float32():
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(5, 7, 3))
    origin = rng.normal(size=(5, 1, 3))
    heading = rng.uniform(-3, 3, size=(5, 1))
    back = world_to_vehicle(vehicle_to_world(pts, origin, heading), origin, heading)
    np.testing.assert_allclose(back, pts, atol=1e-12)
    v32 = rng.normal(size=(100, 3)).astype(np.float32)
    out = rotate(v32, 0.7)
    assert out.dtype == np.float32
    np.testing.assert_allclose(unrotate(out, 0.7), v32, atol=1e-6)
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    np.testing.assert_allclose(point_ahead([1.0, 1.0], math.pi, 2.0), [-1.0, 1.0], atol=1e-12)


def test_footprint_corners_and_extent():
    c = footprint_corners(np.array([[1.0, 2.0]]), np.array([math.pi / 2]), 4.0, 2.0)[0]
    # heading north: front-left is 2 m north and 1 m west of the centre; counter-clockwise
    np.testing.assert_allclose(c, [[0.0, 4.0], [0.0, 0.0], [2.0, 0.0], [2.0, 4.0]], atol=1e-12)
    ex, ey = footprint_extent(2.0, 2.0, math.pi / 4)  # a 2 m square turned 45 deg
    assert ex == pytest.approx(R2) and ey == pytest.approx(R2)
    b = box_corners(np.array([[0.0, 0.0, 0.5]]), np.array([0.0]), [4.0], [2.0], [1.5])[0]
    assert b.min(0) == pytest.approx([-2.0, -1.0, 0.5])
    assert b.max(0) == pytest.approx([2.0, 1.0, 2.0])


def test_slab_and_box_entry_times():
    t0, t1 = slab_interval(10.0, -2.0, 1.0)  # |10 - 2 t| <= 1 for t in [4.5, 5.5]
    assert (t0, t1) == pytest.approx((4.5, 5.5))
    assert slab_interval(0.5, 0.0, 1.0) == (-math.inf, math.inf)  # still, inside
    assert slab_interval(5.0, 0.0, 1.0) == (math.inf, -math.inf)  # still, outside
    p = np.array([[10.0, 3.0], [10.0, 3.0], [0.0, 0.0], [-10.0, 0.0]])
    v = np.array([[-2.0, -1.0], [-2.0, 0.0], [5.0, 5.0], [-1.0, 0.0]])
    t = box_entry_time(p, v, 1.0, 1.0)
    # x in the box for t in [4.5, 5.5], y for t in [2, 4]: never both; second never in y;
    # third already inside; fourth moving away
    assert list(t) == [math.inf, math.inf, 0.0, math.inf]
    t = box_entry_time(np.array([10.0, 3.0]), np.array([-2.0, -0.6]), 1.0, 1.0)
    assert t == pytest.approx(4.5)  # y in [3.33, 6.67], x in [4.5, 5.5]


def test_disc_and_rounded_box_entry():
    assert disc_entry_time(np.array([5.0, 0.0]), np.array([-1.0, 0.0]), 1.0) == pytest.approx(4.0)
    assert disc_entry_time(np.array([5.0, 3.0]), np.array([-1.0, 0.0]), 1.0) == math.inf
    # a disc of 0.5 m heading diagonally at the corner (2, 1) of a 4 x 2 m box: it touches
    # the corner when its centre is 0.5 m from it, before reaching either grown face
    t = rounded_box_entry_time(np.array([5.0, 4.0]), np.array([-1.0, -1.0]), 2.0, 1.0, 0.5)
    assert t == pytest.approx(3.0 - 0.5 / R2)
    # head-on into the front face: the grown box
    t = rounded_box_entry_time(np.array([5.0, 0.0]), np.array([-1.0, 0.0]), 2.0, 1.0, 0.5)
    assert t == pytest.approx(2.5)


def test_footprint_entry_time_conservative_and_exact():
    # ego 4 x 2 m; a 2 m square turned 45 deg, 2.2 m to the left, closing at 1 m/s
    args = (np.array([10.0, 2.2]), np.array([-1.0, 0.0]), math.pi / 4, 4.0, 2.0, 2.0, 2.0)
    # on the ego's axes the square spans +-sqrt(2): overlap once 10 - t <= 2 + sqrt(2)
    assert footprint_entry_time(*args) == pytest.approx(8.0 - R2)
    # exactly, the diamond's lower-left edge meets the ego's front-left corner (2, 1) when
    # |2 - x| + 1.2 <= sqrt(2)
    assert footprint_entry_time(*args, exact=True) == pytest.approx(8.0 - (R2 - 1.2))
    # aligned boxes: both tests agree (rear-end, bumper gap 10 - 3 = 7 m at 2 m/s)
    aligned = (np.array([10.0, 0.5]), np.array([-2.0, 0.0]), 0.0, 4.0, 2.0, 2.0, 2.0)
    assert footprint_entry_time(*aligned) == pytest.approx(3.5)
    assert footprint_entry_time(*aligned, exact=True) == pytest.approx(3.5)


def test_distances_and_gaps():
    assert box_distance(np.array([5.0, 3.0]), 2.0, 1.0) == pytest.approx(math.hypot(3.0, 2.0))
    assert box_distance(np.array([1.0, 0.5]), 2.0, 1.0) == 0.0
    # the same box centred at (1, 1) heading north: the point (1, 6) is 3 m past its front
    d = rectangle_point_distance(np.array([1.0, 1.0]), math.pi / 2, 2.0, 1.0, np.array([1.0, 6.0]))
    assert d == pytest.approx(3.0)
    along, across = bumper_gap(np.array([[20.0, 0.5], [3.0, 2.5]]), 4.8, 1.9, 5.3, 1.9)
    assert along == pytest.approx([20.0 - 5.05, 3.0 - 5.05])
    assert across == pytest.approx([0.5 - 1.9, 2.5 - 1.9])


def _actors(rows):
    a = np.array(rows, dtype=float)  # x, y, heading, speed, length, width
    return a[:, :2], a[:, 2], a[:, 3], a[:, 4], a[:, 5]


def test_ground_truth_ttc_and_gap_by_hand():
    xy, heading, speed, length, width = _actors(
        [
            [0.0, 0.0, 0.0, 20.0, 4.8, 1.9],  # ego
            [30.0, 0.0, 0.0, 10.0, 4.0, 2.0],  # lead, 10 m/s slower
            [20.0, -4.0, math.pi / 2, 1.5, 4.0, 2.0],  # crossing from the right
            [20.0, 5.0, 0.0, 0.0, 4.0, 2.0],  # parked one lane over
            [400.0, 0.0, 0.0, 0.0, 4.0, 2.0],  # far ahead: 19.6 s away
            [50.0, 0.0, math.pi / 2, 0.3, 4.0, 2.0],  # barely moving: taken aligned
        ]
    )
    ttc = time_to_collision(xy, heading, speed, length, width, 0)
    assert ttc[0] == math.inf
    assert ttc[1] == pytest.approx((30.0 - 4.4) / 10.0)
    # heading along its velocity, the crossing car spans 1 m along the ego's x: longitudinal
    # overlap from (20 - 1 - 2.4) / 20 s, lateral from (4 - 1 - 0.95) / 1.5 s
    assert ttc[2] == pytest.approx(16.6 / 20.0)
    assert ttc[3] == math.inf
    assert ttc[4] == math.inf  # beyond the 10 s horizon
    assert time_to_collision(xy, heading, speed, length, width, 0, TruthConfig(30.0))[
        4
    ] == pytest.approx((400.0 - 4.4) / 20.0)
    assert ttc[5] == pytest.approx((50.0 - 4.4) / 20.0, rel=1e-3)  # 4 m long along the ego
    along, across = gap_to(xy, heading, length, width, 0, 1)
    assert along == pytest.approx(25.6) and across < 0
    along, across = gap_to(xy, heading, length, width, 0, 3)
    assert across == pytest.approx(5.0 - 1.95)
