"""New perception disturbances: snow, spray, per-sensor window soiling (hand-computed)."""

from __future__ import annotations

import math

import pytest

from hiyari.errors import HiyariError
from hiyari.sensors.environment.atmosphere import AtmosphereModel
from hiyari.sensors.environment.conditions import Environment, Soiling


def test_snow_extinction_and_radar_attenuation_by_hand():
    atm = AtmosphereModel()
    env = Environment(snow_visibility_m=400.0)
    # Koschmieder: -ln(0.02) / 400 m = 3.912 / 400 = 0.00978 /m, the same for LiDAR and light
    assert atm.lidar_extinction(env) == pytest.approx(3.912 / 400.0, rel=1e-3)
    assert atm.visible_extinction(env) == pytest.approx(3.912 / 400.0, rel=1e-3)
    # 400 m visibility -> 2.5 mm/h water; ITU-R P.838 at 77 GHz: 0.94 * 2.5^0.78 dB/km
    assert atm.radar_attenuation_db_per_m(env) == pytest.approx(0.94 * 2.5**0.78 / 1000, rel=1e-9)


def test_spray_attenuates_light_but_not_radar():
    atm = AtmosphereModel()
    env = Environment(spray_visibility_m=50.0)
    assert atm.visible_extinction(env) == pytest.approx(3.912 / 50.0, rel=1e-3)
    assert atm.radar_attenuation_db_per_m(env) == 0.0


def test_window_soiling_per_sensor():
    dirty = Soiling(uniform_transmission=0.5)
    env = Environment(sensor_soiling=(("lidar", dirty),))
    assert env.for_sensor("lidar").soiling.uniform_transmission == 0.5
    assert env.for_sensor("radar").soiling.uniform_transmission == 1.0
    with pytest.raises(HiyariError, match="unknown sensor 'sonar'"):
        Environment(sensor_soiling=(("sonar", dirty),))
    with pytest.raises(HiyariError, match="snow_visibility_m"):
        Environment(snow_visibility_m=0.0)
    assert math.isinf(Environment().snow_visibility_m)
