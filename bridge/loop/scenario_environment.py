"""A scenario's EnvironmentAction as the ego's perception disturbance and grip: rain, snow,
fog, daylight and the sun from the OpenSCENARIO Environment, the road's friction scaling the
decelerations the ego's planner may command.

Daylight from the sun's illuminance: below 10 lx night, below 1000 lx dusk, else day (CIE
twilight levels: civil twilight ends near 3 lx, an overcast day is above 1000 lx). OpenSCENARIO's
sun azimuth (from north, clockwise) becomes the network frame's (from +x, counter-clockwise;
the network's +y taken as north). Precipitation intensity (mm/h): rain directly; snow as the
visibility it leaves, 1000 / (1 + intensity) m (an assumption of this module: heavy snow of
10 mm/h water equivalent leaves about 90 m).
"""

from __future__ import annotations

import math
from dataclasses import replace

from hiyari.bridge.openscenario.model.global_actions import Environment as ScenarioEnvironment
from hiyari.sensors.environment.conditions import Environment, Illumination
from hiyari.sensors.environment.presets import DisturbancePreset

#: Sun illuminance (lx) below which it is night, and dusk.
NIGHT_LUX, DUSK_LUX = 10.0, 1000.0


def disturbance_from(env: ScenarioEnvironment) -> DisturbancePreset:
    """The perception disturbance of the scenario environment ``env`` (the sun where the file
    puts it, not relative to the ego)."""
    out = Environment()
    w = env.weather
    if w is not None:
        if w.fog is not None:
            out = replace(out, fog_visibility_m=max(w.fog.visual_range, 1.0))
        if w.precipitation is not None and w.precipitation.intensity:
            p = w.precipitation
            if p.kind == "rain":
                out = replace(out, rain_mm_h=p.intensity)
            elif p.kind == "snow":
                out = replace(out, snow_visibility_m=1000.0 / (1.0 + p.intensity))
        if w.sun is not None:
            lux = w.sun.illuminance
            light = Illumination.DAY
            if lux is not None and lux < NIGHT_LUX:
                light = Illumination.NIGHT
            elif lux is not None and lux < DUSK_LUX:
                light = Illumination.DUSK
            azimuth = (90.0 - math.degrees(w.sun.azimuth) + 180.0) % 360.0 - 180.0
            out = replace(
                out,
                illumination=light,
                headlights=light != Illumination.DAY,
                sun_azimuth_deg=azimuth,
                sun_elevation_deg=max(0.0, math.degrees(w.sun.elevation)),
            )
    return DisturbancePreset(
        f"scenario:{env.name}", "the scenario's EnvironmentAction", out.validate(),
        sun_relative_azimuth_deg=None,
    )  # fmt: skip


def grip(env: ScenarioEnvironment | None) -> float:
    """The road's friction relative to dry asphalt (1 when the scenario gives none)."""
    if env is None or env.road is None:
        return 1.0
    return max(0.0, env.road.friction_scale)
