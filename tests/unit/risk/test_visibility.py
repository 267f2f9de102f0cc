"""Line of sight in the ground truth (hiyari.risk.metrics.visibility), on layouts worked by hand:
ego at the origin heading +x, a 4.5 x 1.8 m car 30 m ahead, a 10 x 2.5 m truck between them."""

from __future__ import annotations

import numpy as np

from hiyari.risk.metrics.visibility import in_line_of_sight

LENGTH = np.array([4.5, 4.5, 10.0])
WIDTH = np.array([1.8, 1.8, 2.5])


def _seen(truck_xy: tuple[float, float], truck_heading: float = 0.0) -> bool:
    xy = np.array([[0.0, 0.0], [30.0, 0.0], truck_xy])
    heading = np.array([0.0, 0.0, truck_heading])
    return in_line_of_sight(xy, heading, LENGTH, WIDTH, viewer=0, target=1)


def test_a_truck_in_the_lane_hides_the_car_behind_it():
    assert not _seen((15.0, 0.0))


def test_the_truck_in_the_next_lane_hides_nothing():
    assert _seen((15.0, 3.5))


def test_a_car_partly_hidden_is_in_sight():
    # the truck's left side at y = 0.25 + 1.25 = 1.5 m; the line to the car's front-left corner
    # (27.75, 0.9) passes y = 0.49 at x = 15 -> inside the truck (blocked); the line to the rear
    # corner (32.25, 0.9) too. Shift the truck right so that its left side is at y = 0.0: the
    # car's left corners (y = 0.9) show past it.
    assert not _seen((15.0, 0.25))
    assert _seen((15.0, -1.25))


def test_a_truck_behind_the_ego_or_beyond_the_car_hides_nothing():
    assert _seen((-15.0, 0.0))
    assert _seen((45.0, 0.0))


def test_a_truck_across_the_road_hides_the_car():
    assert not _seen((15.0, 0.0), np.pi / 2)


def test_alone_the_target_is_in_sight():
    xy = np.array([[0.0, 0.0], [30.0, 0.0]])
    assert in_line_of_sight(xy, np.zeros(2), LENGTH[:2], WIDTH[:2], 0, 1)
