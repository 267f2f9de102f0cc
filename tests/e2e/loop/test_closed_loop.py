"""End-to-end closed loop on real SUMO: dart-out, cut-in, stationary car, sensors disabled."""

from __future__ import annotations

import pytest
from runs import run_preset

from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario


def _cs(stype, params, perception="perfect", duration=15.0, **kw):
    return ConcreteScenario(stype, stype, 0, 1, duration, 0.05, params, perception=perception, **kw)


DART = {"ve0_kmh": 40.0, "ped_speed_kmh": 5.0, "impact_fraction": 0.5}


def test_dart_out_perfect_perception_stops_short():
    r = run_preset(_cs("dart-out", DART))
    assert not r.collision
    assert r.aeb_max_stage == 3
    # stopped before reaching the point where the child would have been hit
    assert 0.0 < r.stop_distance < 10.0


def test_dart_out_without_sensors_collides():
    r = run_preset(_cs("dart-out", DART, perception="none"))
    assert r.collision and r.collided_with == "child"
    assert r.impact_speed == pytest.approx(40 / 3.6, abs=0.01)  # never braked


def test_dart_out_same_seed_same_result():
    a = run_preset(_cs("dart-out", DART))
    b = run_preset(_cs("dart-out", DART))
    assert a.series == b.series


def test_stationary_car_approach():
    ok = run_preset(_cs("stationary", {"ve0_kmh": 50.0, "gap_m": 100.0}, duration=20.0))
    assert not ok.collision and min(ok.series.ego_speed) < 0.05
    assert 0.0 < ok.min_gap < 5.0
    blind = run_preset(_cs("stationary", {"ve0_kmh": 50.0, "gap_m": 100.0}, "none", 20.0))
    assert blind.collision and blind.collided_with == "other"


def test_cut_in_inside_preventable_region_is_passed():
    # Vo0 much slower than the ego, gap well above any C&C boundary at these speeds
    r = run_preset(
        _cs(
            "cut-in", {"ve0_kmh": 60.0, "vo0_kmh": 30.0, "dx0_m": 40.0, "vy_ms": 1.0}, duration=20.0
        )
    )
    assert not r.collision
    assert r.min_gap > 0.0
    blind = run_preset(
        _cs("cut-in", {"ve0_kmh": 60.0, "vo0_kmh": 30.0, "dx0_m": 40.0, "vy_ms": 1.0}, "none", 20.0)
    )
    assert blind.collision and blind.collided_with == "other"


def test_dart_out_with_full_sensor_stack_stops_short():
    r = run_preset(_cs("dart-out", DART, "sensors", environment="clear"))
    assert not r.collision
    assert r.detection["camera"].target_frames > 0 and r.detection["lidar"].target_frames > 0


def test_night_dark_clothing_camera_only_worse_than_camera_lidar():
    """DIVP: the camera ranges a dark-clothed pedestrian at night poorly, LiDAR ranges it well:
    camera + LiDAR stops with more room to spare than the camera alone (or the camera alone
    does not stop at all)."""
    env = "night_headlights_dark_clothing"
    for v in (40.0, 50.0):
        crossing = {**DART, "ve0_kmh": v, "parked_car": 0.0}
        cam = run_preset(_cs("dart-out", crossing, "sensors", sensors=("camera",), environment=env))
        both = run_preset(
            _cs("dart-out", crossing, "sensors", sensors=("camera", "lidar"), environment=env)
        )
        assert not both.collision
        assert cam.collision or cam.stop_distance < both.stop_distance - 0.3, (v, cam, both)
        assert both.detection["lidar"].target_frames > 0
