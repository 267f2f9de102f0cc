"""A vehicle crossing the ego's path at right angles keeps its sideways speed in the fusion
(issue 29: Euro NCAP CCCscp scored 0 because the stack rated the crossing car as parked),
while noise on a parked car's track is still clipped (FusionConfig.slip_noise_sigmas)."""

from __future__ import annotations

import numpy as np

from hiyari.bridge.loop.stack.aeb import AEBConfig, time_to_collision
from hiyari.bridge.loop.stack.fusion import KalmanFusion
from hiyari.kinematics import Pose
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.actor_class import ActorClass

DT = 0.05
EGO_SPEED = 20 / 3.6  # m/s, CCCscp at 20 km/h
CAR_SPEED = 20 / 3.6  # m/s, the target crossing from the ego's left


def _truth(time: float, xy: np.ndarray, vel: np.ndarray, ego: Pose) -> ObjectList:
    """What perfect perception reports of one car: ego frame, velocity relative to the ego."""
    c, s = np.cos(ego.heading), np.sin(ego.heading)
    rot = np.array([[c, s], [-s, c]])  # world -> ego
    rel = rot @ (xy - np.array([ego.x, ego.y]))
    rel_v = rot @ (vel - ego.velocity)
    return ObjectList(
        time, "truth", ego.to_world(), np.array([1]), np.array([ActorClass.CAR], np.int8),
        np.array([[rel[0], rel[1], 0.0]]), np.array([[rel_v[0], rel_v[1], 0.0]]),
        np.array([[4.6, 1.8, 1.5]]), np.ones(1), np.array(["target"], dtype=object),
    )  # fmt: skip


def test_a_car_crossing_at_right_angles_keeps_its_sideways_speed_and_is_a_threat():
    """Ego heading +y in the world (any heading: the clip is in the ego's frame) at 20 km/h;
    a car from its left at 20 km/h crossing at right angles, both reaching the crossing point
    (0, 30) together: the impact is at about 30 / 5.56 = 5.4 s minus the half lengths and
    widths. After 1 s of tracking the fused car must move sideways at 5.56 m/s in the ego's
    frame (it was clipped to 0: a parked car) and its stack TTC must be within 0.3 s of the
    constant-velocity TTC of the true states (it was infinite)."""
    fusion = KalmanFusion()
    heading = np.pi / 2
    out = None
    for k in range(21):
        t = k * DT
        ego = Pose(0.0, EGO_SPEED * t, 0.0, heading, EGO_SPEED, 0.0, 4.8, 1.9)
        car_xy = np.array([-30.0 + CAR_SPEED * t, 30.0])
        car_v = np.array([CAR_SPEED, 0.0])
        out = fusion.update([_truth(t, car_xy, car_v, ego)], ego, t)
    assert out is not None and len(out) == 1
    # over ground, on the ego's axes: forward 0, sideways to the ego's right (-y) at 5.56 m/s
    v_ground = out.velocity[0, :2] + np.array([EGO_SPEED, 0.0])
    assert abs(v_ground[0]) < 0.2
    assert abs(v_ground[1] + CAR_SPEED) < 0.2
    # true TTC: ego front at y = 5.56 t + 2.4 meets the car's near side y = 30 - 0.9 ...
    # both move: the slab test on the true relative state gives it exactly
    rel = out.position[0, :2]
    true = ObjectList(
        out.time, "truth", ego.to_world(), np.array([1]), out.cls, out.position,
        np.array([[-EGO_SPEED, -CAR_SPEED, 0.0]]), out.size, np.ones(1), out.truth,
    )  # fmt: skip
    expected = time_to_collision(true, ego, AEBConfig())[0]
    stack = time_to_collision(out, ego, AEBConfig())[0]
    assert np.isfinite(expected) and rel[0] > 0
    assert abs(stack - expected) < 0.3


def test_a_parked_car_seen_with_noise_stays_at_rest():
    """A parked car 30 m ahead, 3 m to the right, seen at 20 Hz with 0.1 m of position noise
    (within a LiDAR's sigmas): the sideways speed its track estimates is noise, inside the
    slip rule's sigmas, so the car is still reported at rest (one track, zero velocity)."""
    rng = np.random.default_rng(3)
    fusion = KalmanFusion()
    out = None
    for k in range(40):
        t = k * DT
        ego = Pose(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 4.8, 1.9)
        xy = np.array([30.0, -3.0]) + rng.normal(0.0, 0.1, 2)
        ol = ObjectList(
            t, "lidar", ego.to_world(), np.array([1]), np.array([ActorClass.CAR], np.int8),
            np.array([[xy[0], xy[1], 0.0]]), np.full((1, 3), np.nan),
            np.array([[4.6, 1.8, 1.5]]), np.ones(1), np.array(["parked"], dtype=object),
        )  # fmt: skip
        out = fusion.update([ol], ego, t)
    assert out is not None and len(out) == 1
    assert np.all(out.velocity[0, :2] == 0.0)
