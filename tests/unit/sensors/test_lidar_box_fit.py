"""L-shape box fitting of LiDAR clusters: hand-built outlines, a progressive reveal, a real scan.

Hand-built point sets are the faces of a box a sensor at the origin sees (2 cm noise, seeded);
the expected centres and headings are the box's own, computed by hand from its corners.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.box_fit import BoxFitConfig, complete_boxes, fit_rectangles
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, actor_world
from hiyari.traffic.actor_class import ActorClass

TRUCK = (8.0, 2.5)
CAR = (4.5, 1.8)


def face(a: tuple[float, float], b: tuple[float, float], step: float = 0.05) -> np.ndarray:
    """Points every ``step`` m on the segment a-b, eight returns (channels) per azimuth."""
    n = max(2, int(math.dist(a, b) / step) + 1)
    t = np.linspace(0.0, 1.0, n)
    pts = np.asarray(a) + t[:, None] * (np.asarray(b) - np.asarray(a))
    return np.repeat(pts, 8, axis=0)


def corners(cx: float, cy: float, heading: float, size: tuple[float, float]) -> dict:
    """Rear-right, rear-left, front-left, front-right corners of a box, m."""
    c, s = math.cos(heading), math.sin(heading)
    half_l, half_w = size[0] / 2, size[1] / 2

    def at(u: float, v: float) -> tuple[float, float]:
        return (cx + c * u - s * v, cy + s * u + c * v)

    return dict(
        rr=at(-half_l, -half_w),
        rl=at(-half_l, half_w),
        fl=at(half_l, half_w),
        fr=at(half_l, -half_w),
    )


def fit(
    points: np.ndarray, prior: tuple[float, float], seed: int = 0
) -> tuple[np.ndarray, float, np.ndarray]:
    """Centre (2,), heading (rad, network frame) and length/width of one noisy point set
    seen from a sensor at the origin heading +x."""
    pts = points + np.random.default_rng(seed).normal(0.0, 0.02, points.shape)
    cfg = BoxFitConfig()
    rect = fit_rectangles(
        pts,
        np.arange(len(pts)),
        np.array([0, len(pts)]),
        np.array([0]),
        (
            cfg.merge_cell_m,
            cfg.closeness_floor_m,
            math.radians(cfg.coarse_step_deg),
            math.radians(cfg.fine_step_deg),
        ),
    )
    centre, heading, dims = complete_boxes(
        rect, np.array([prior[0]]), np.array([prior[1]]), 0.0, cfg.length_margin_m
    )
    return centre[0], float(heading[0]), dims[0]


def cross(u: np.ndarray, v: np.ndarray) -> float:
    """z of the 2D cross product u x v."""
    return float(u[0] * v[1] - u[1] * v[0])


def angle_error(a: float, b: float) -> float:
    """Difference of two box headings (defined modulo pi), rad."""
    return abs((a - b + math.pi / 2) % math.pi - math.pi / 2)


def test_one_visible_side_of_a_truck_beside_the_sensor():
    # truck centred at (10, 4) along +x: the sensor sees its whole right side at y = 2.75
    k = corners(10.0, 4.0, 0.0, TRUCK)
    centre, heading, dims = fit(face(k["rr"], k["fr"]), TRUCK)
    np.testing.assert_allclose(centre, [10.0, 4.0], atol=0.1)
    assert angle_error(heading, 0.0) < math.radians(1.0)
    np.testing.assert_allclose(dims, TRUCK, atol=0.1)


@pytest.mark.parametrize("heading_deg", [25.0, -40.0, 110.0])
def test_l_corner_of_a_rotated_car(heading_deg: float):
    # a car ahead-right, turned: the sensor sees the two faces towards it, the second only
    # from the shared corner on (its far 40 % hidden)
    h = math.radians(heading_deg)
    cx, cy = 12.0, -5.0
    k = corners(cx, cy, h, CAR)
    seen = [
        (k[a], k[b])
        for a, b in (("rr", "rl"), ("rl", "fl"), ("fl", "fr"), ("fr", "rr"))
        if cross(np.subtract(k[b], k[a]), np.negative(k[a])) > 0  # outward normal to 0
    ]
    assert len(seen) == 2
    if seen[1][1] == seen[0][0]:  # the pair wraps round the corner list
        seen = seen[::-1]
    (a0, b0), (a1, b1) = seen
    partial = np.asarray(a1) + 0.6 * (np.asarray(b1) - np.asarray(a1))
    pts = np.concatenate([face(a0, b0), face(a1, tuple(partial))])
    centre, heading, dims = fit(pts, CAR)
    assert angle_error(heading, h) < math.radians(1.5)
    # the first face ends where the partly hidden one starts: the corner pins the box
    np.testing.assert_allclose(centre, [cx, cy], atol=0.15)
    np.testing.assert_allclose(dims, CAR, atol=0.15)


def test_rear_face_only_extends_the_car_away_from_the_sensor():
    # a car 15 m ahead seen squarely from behind: only its rear (1.8 m) is visible
    k = corners(15.0, 0.3, 0.0, CAR)
    centre, heading, dims = fit(face(k["rr"], k["rl"]), CAR)
    np.testing.assert_allclose(centre, [15.0, 0.3], atol=0.1)
    assert angle_error(heading, 0.0) < math.radians(1.0)
    np.testing.assert_allclose(dims, CAR, atol=0.1)


def test_progressively_revealed_truck_keeps_its_centre_while_the_centroid_drifts():
    # a truck ahead-left (centre (9, 3.5)) whose rear is visible and whose side comes into
    # view from the rear forwards, 1 m to all 8 m, as an occluder ahead uncovers it
    k = corners(9.0, 3.5, 0.0, TRUCK)
    centres, centroids = [], []
    for seen in np.arange(1.0, 8.01, 0.5):
        side = face(k["rr"], (k["rr"][0] + seen, k["rr"][1]))
        pts = np.concatenate([face(k["rr"], k["rl"]), side])
        centre, heading, _ = fit(pts, TRUCK, seed=int(seen * 2))
        assert angle_error(heading, 0.0) < math.radians(1.5)
        centres.append(centre)
        centroids.append(pts.mean(0))
    centres, centroids = np.array(centres), np.array(centroids)
    assert np.max(np.linalg.norm(centres - [9.0, 3.5], axis=1)) < 0.3
    assert np.ptp(centroids[:, 0]) > 2.0  # the visible points' centroid moves by metres


def test_real_scan_of_a_truck_in_the_next_lane():
    # 64-channel LiDAR at 1.9 m on the ego in the right lane; a truck 10 m ahead in the left
    # lane (3.5 m to the left): it shows its rear and right side
    world = actor_world(
        [
            dict(id="ego", cls=ActorClass.CAR, x=0.0, y=-1.75),
            dict(id="truck", cls=ActorClass.TRUCK, x=10.0, y=1.75, heading=math.radians(5.0)),
        ]
    )
    scene = RayScene(StraightRoad().mesh())
    scene.update(world, "ego")
    lidar = Lidar(LidarConfig.preset("64ch"), Mount(x=0.0, z=1.9))
    cloud, objects = lidar.sense(
        scene, world.pose_of("ego"), world, Environment(), np.random.default_rng(1)
    )
    k = int(np.flatnonzero(objects.truth == "truck")[0])
    assert objects.cls[k] == ActorClass.TRUCK
    # sensor frame = ego frame shifted up 1.9 m: the truck's centre is at (10, 3.5)
    np.testing.assert_allclose(objects.position[k, :2], [10.0, 3.5], atol=0.3)
    assert angle_error(float(objects.heading[k]), math.radians(5.0)) < math.radians(2.0)
    np.testing.assert_allclose(objects.size[k, :2], TRUCK, atol=0.3)
    # the visible points' centroid is well off the centre (the far side is not seen)
    pts = cloud.xyz[cloud.truth_ids() == "truck", :2]
    assert np.linalg.norm(pts.mean(0) - [10.0, 3.5]) > 1.0
