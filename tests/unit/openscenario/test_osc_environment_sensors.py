"""The scenario's EnvironmentAction as perception disturbance and grip: the Euro NCAP night
(moon at 0.1 lx) is night with the ego's low beams, rain and fog carry over, the sun is placed
in the network frame, and the road's friction scales the planner's decelerations."""

from __future__ import annotations

import math

import pytest

from hiyari.bridge.loop.scenario_environment import disturbance_from, grip
from hiyari.bridge.loop.spec import EgoSetup, StackContext, default_stack
from hiyari.bridge.openscenario.model.global_actions import (
    Environment,
    Fog,
    Precipitation,
    RoadCondition,
    Sun,
    Weather,
)
from hiyari.sensors.environment.conditions import Illumination


def test_night_rain_fog_and_sun() -> None:
    night = Environment("Night", weather=Weather(sun=Sun(math.radians(178), math.radians(66), 0.1)))
    env = disturbance_from(night).environment
    assert env.illumination == Illumination.NIGHT and env.headlights
    assert env.sun_azimuth_deg == pytest.approx(90 - 178)  # 178 deg from north: just west of south
    wet = Environment("Wet", weather=Weather(fog=Fog(80.0), precipitation=Precipitation("rain", 2.5),
                                             sun=Sun(0.0, math.radians(30), 50000.0)))  # fmt: skip
    env = disturbance_from(wet).environment
    assert (
        env.rain_mm_h == 2.5
        and env.fog_visibility_m == 80.0
        and env.illumination == Illumination.DAY
    )
    assert env.sun_azimuth_deg == pytest.approx(90.0) and env.sun_elevation_deg == pytest.approx(
        30.0
    )
    snow = Environment("Snow", weather=Weather(precipitation=Precipitation("snow", 9.0)))
    assert disturbance_from(snow).environment.snow_visibility_m == pytest.approx(100.0)


def test_friction_scales_the_planner() -> None:
    icy = Environment("Icy", road=RoadCondition(0.5, "icy"))
    assert grip(icy) == 0.5 and grip(None) == 1.0
    ctx = StackContext(
        None, EgoSetup(), "Ego", 15.0, None, environment=icy
    )  # perfect perception: no road needed
    planner = default_stack(ctx).planner
    assert planner.aeb.full_decel_g == pytest.approx(
        0.4
    ) and planner.acc.max_decel == pytest.approx(1.5)
