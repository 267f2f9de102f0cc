"""Ego stack pieces against hand-computed values: TTC geometry, AEB staging and delay, fusion."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from hiyari.bridge.loop.stack.aeb import (
    AEBConfig,
    AEBPlanner,
    AEBStage,
    time_to_collision,
    track_extent,
)
from hiyari.bridge.loop.stack.fusion import FusionConfig, KalmanFusion
from hiyari.kinematics import Pose
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.actor_class import ActorClass

EGO = Pose(0.0, 0.0, 0.0, 0.0, 20.0, 0.0, 4.8, 1.9)


def _objs(pos, vel, size, source="truth", truth=None, frame=None, cls=0):
    n = len(pos)
    p3 = np.zeros((n, 3))
    p3[:, :2] = pos
    v3 = np.zeros((n, 3))
    v3[:, :2] = vel
    return ObjectList(
        0.0,
        source,
        np.eye(4) if frame is None else frame,
        np.arange(n),
        np.full(n, cls, np.int8),
        p3,
        v3,
        np.array(size, dtype=float),
        np.ones(n),
        np.array(truth or ["t"] * n, dtype=object),
    )


def test_ttc_rear_end_and_crossing_by_hand():
    cfg = AEBConfig(lateral_margin=0.0)
    tracks = _objs(
        pos=[[30.0, 0.0], [30.0, 5.0], [20.0, -4.0], [20.0, 3.0]],
        vel=[[-10.0, 0.0], [-10.0, 0.0], [-20.0, 1.5], [0.0, 0.0]],
        size=[[4.0, 2.0, 1.5]] * 4,
    )
    ttc = time_to_collision(tracks, EGO, cfg)
    # car ahead closing at 10 m/s: bumper gap 30 - (4 + 4.8)/2 = 25.6 m -> 2.56 s
    assert ttc[0] == pytest.approx(2.56)
    # same car one lane over (5 m left) never overlaps laterally
    assert ttc[1] == math.inf
    # a car crossing from the right at 1.5 m/s over ground (the ego does 20 m/s), so it
    # heads across the road: its footprint spans 1 m along the ego's x and 2 m along y.
    # Longitudinal overlap while |20 - 20 t| <= 1 + 2.4, i.e. t in [0.83, 1.17];
    # lateral while |-4 + 1.5 t| <= 2 + 0.95, i.e. t in [0.7, 4.63]: first contact 0.83 s
    assert ttc[2] == pytest.approx(16.6 / 20.0)
    # a parked car beside the path is no threat
    assert ttc[3] == math.inf


def test_footprint_extent_follows_heading():
    # Annex G: a car cutting in at Vy = 1 m/s while doing 10 m/s heads atan(0.1) off the road
    ego = Pose(0.0, 0.0, 0.0, 0.0, 15.0, 0.0, 4.8, 1.9)
    tracks = _objs([[20.0, 3.5]], [[-5.0, -1.0]], [[5.3, 1.9, 1.5]])
    ext_x, ext_y = track_extent(tracks, ego)
    psi = math.atan2(1.0, 10.0)
    assert ext_y[0] == pytest.approx((5.3 * math.sin(psi) + 1.9 * math.cos(psi)) / 2)
    assert ext_x[0] == pytest.approx((5.3 * math.cos(psi) + 1.9 * math.sin(psi)) / 2)


def test_aeb_stages_and_actuation_delay():
    cfg = AEBConfig(actuation_delay=0.2, latch_until_stop=False)
    planner = AEBPlanner(aeb=cfg)
    dt = 0.05
    decels, stages = [], []
    for k in range(20):
        t = k * dt
        gap = 4.4 + 20.0 - 20.0 * t  # closing at 20 m/s from a 20 m bumper gap (TTC 1.0 - t)
        cmd = planner.plan(_objs([[gap, 0.0]], [[-20.0, 0.0]], [[4.0, 2.0, 1.5]]), EGO, t)
        decels.append(cmd.aeb_decel)
        stages.append(cmd.aeb_stage)
    # TTC starts at 1.0 s -> PARTIAL; below 1.0 s -> FULL
    assert stages[0] == AEBStage.PARTIAL and stages[1] == AEBStage.FULL
    # nothing applied during the 0.2 s delay, then the step-0 (partial) and step-1 (full) decisions
    assert decels[:4] == [0.0] * 4
    assert decels[4] == pytest.approx(0.4 * 9.81)
    assert decels[5] == pytest.approx(0.8 * 9.81)


def _track_cv_target(noise: float, seed: int = 0) -> list[np.ndarray]:
    fusion = KalmanFusion()
    rng = np.random.default_rng(seed)
    ego = Pose(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 4.8, 1.9)
    vel = []
    for k in range(60):
        t = k * 0.1
        meas = np.array([50.0 - 8.0 * t, 2.0 + 0.5 * t]) + rng.normal(0, noise, 2)
        lidar = ObjectList(
            t,
            "lidar",
            np.eye(4),
            np.array([0]),
            np.array([0], np.int8),
            np.array([[meas[0], meas[1], 0.0]]),
            np.full((1, 3), np.nan),
            np.full((1, 3), np.nan),
            np.ones(1),
            np.array(["car"], dtype=object),
        )
        out = fusion.update([lidar], ego, t)
        if len(out):
            assert len(out) == 1 and out.truth[0] == "car"
            vel.append(out.velocity[0, :2])
    return vel


def test_kalman_fusion_tracks_constant_velocity_target():
    # exact measurements: the constant-velocity filter converges to the true velocity
    assert _track_cv_target(0.0)[-1] == pytest.approx([-8.0, 0.5], abs=1e-3)
    # 0.1 m LiDAR noise: velocity error over the last 2 s stays well below 1 m/s (RMS)
    err = np.array(_track_cv_target(0.1)[-20:]) - [-8.0, 0.5]
    assert np.sqrt((err**2).mean()) < 0.6


def test_camera_bearing_fused_with_radar_range():
    """Camera gives class and bearing, radar gives range: the fused object takes both, its
    centre behind the radar's point on the visible face (FusionConfig.radar_face_depth)."""
    fusion = KalmanFusion()
    ego = Pose(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 4.8, 1.9)
    bearing = math.radians(2.0)
    for k in range(3):
        t = k * 0.1
        cam = _objs(
            [[35.0 * math.cos(bearing), 35.0 * math.sin(bearing)]],
            [[np.nan, np.nan]],
            [[np.nan] * 3],
            source="camera",
            truth=["ped"],
            cls=5,
        )
        radar = _objs(
            [[40.0, 1.9]], [[0.0, 0.0]], [[np.nan] * 3], source="radar", truth=["ped"], cls=-1
        )
        out = fusion.update([cam, radar], ego, t)
    assert len(out) == 1
    assert out.cls[0] == 5  # from the camera
    # a pedestrian at rest, seen 2 deg off its axis: its half depth along the line of sight
    length, width, _ = ActorClass.PEDESTRIAN.size.as_tuple()
    depth = 0.5 * (length * math.cos(bearing) + width * math.sin(bearing))
    r = math.hypot(40.0, 1.9) + FusionConfig().radar_face_depth[0] * depth
    assert out.position[0, 0] == pytest.approx(r * math.cos(bearing), abs=0.05)
    assert out.position[0, 1] == pytest.approx(r * math.sin(bearing), abs=0.05)


def test_aeb_ignores_what_comes_from_behind():
    # a car 13 m behind in the ego's lane closing at 10 m/s: rear bumper gap 13 - 4.4 = 8.6 m,
    # TTC 0.86 s, yet braking would only raise the impact speed; the same car ahead (closing)
    # is a full-brake threat. M05-left_rear-2L-000 braked fully for the first (issue #30).
    behind = _objs([[-13.0, 0.0]], [[10.0, 0.0]], [[4.0, 2.0, 1.5]])
    ahead = _objs([[13.0, 0.0]], [[-10.0, 0.0]], [[4.0, 2.0, 1.5]])
    assert time_to_collision(behind, EGO, AEBConfig(lateral_margin=0.0))[0] == pytest.approx(0.86)
    cmd = AEBPlanner().plan(behind, EGO, 0.0)
    assert cmd.aeb_stage == AEBStage.OFF and cmd.ttc == math.inf and cmd.threat == ""
    assert AEBPlanner().plan(ahead, EGO, 0.0).aeb_stage == AEBStage.FULL
    # beside the ego, cutting in at 2 m/s over 20 m/s (heading atan(0.1): half extent along
    # x 2.09 m): centre 0.2 m ahead, its front 2.29 m, 0.11 m behind the ego's (2.4 m): not
    # braked for; centre 0.6 m ahead, its front leads the ego's: braked for
    beside = _objs([[0.2, 2.5]], [[0.0, -2.0]], [[4.0, 2.0, 1.5]])
    assert AEBPlanner().plan(beside, EGO, 0.0).aeb_stage == AEBStage.OFF
    level = _objs([[0.6, 2.5]], [[0.0, -2.0]], [[4.0, 2.0, 1.5]])
    assert AEBPlanner().plan(level, EGO, 0.0).aeb_stage > AEBStage.OFF


def test_a_heading_within_the_velocity_noise_is_not_taken():
    """Motorway catalogue M24-front-3L-000 with sensors (issue #30): a car standing to the
    ego's left, its track 2.44 m off the ego's axis (the car's centre 2.57 m), 31 m ahead, the
    ego at 23.94 m/s. Its track moved at 1.36 m/s over ground (-1.35 along, -0.15 sideways)
    with a velocity sigma of 0.67 m/s. Taken along that velocity its footprint turned 6 degrees: half extent sideways
    (4.64 sin 6.3 deg + 1.87 cos 6.3 deg) / 2 = 1.18 m, so at the longitudinal overlap from
    (31 - 2.32 - 2.4) / 25.29 = 1.04 s its side at 2.44 - 0.16 - 1.18 = 1.10 m was inside the
    widened ego's 0.95 + 0.2 = 1.15 m: TTC 1.04 s, partial braking. Aligned with the ego (the
    speed is within 3 sigma of zero) its side stays at 2.28 - 0.935 = 1.35 m: no threat."""
    ego = Pose(0.0, 0.0, 0.0, 0.0, 23.94, 0.0, 4.8, 1.9)
    tracks = _objs([[31.0, 2.44]], [[-25.29, -0.15]], [[4.64, 1.87, 1.5]])
    cfg = AEBConfig()
    assert time_to_collision(tracks, ego, cfg)[0] == pytest.approx(1.04, abs=0.01)  # no sigma
    noisy = replace(tracks, velocity_sigma=np.array([0.67]))
    assert time_to_collision(noisy, ego, cfg)[0] == math.inf
    # a car crossing at 1.5 m/s known to 0.3 m/s keeps its heading across the road
    crossing = replace(
        _objs([[16.6, -4.0]], [[-20.0, 1.5]], [[4.5, 1.8, 1.5]]), velocity_sigma=np.array([0.3])
    )
    ext_x, ext_y = track_extent(crossing, Pose(0.0, 0.0, 0.0, 0.0, 20.0, 0.0, 4.8, 1.9))
    assert ext_y[0] == pytest.approx(2.25) and ext_x[0] == pytest.approx(0.9)
