"""Perception-disturbance presets named after the JAMA factor tree (jama-B section 9, jama-C).

A preset sets the shared Environment (weather, light, sun, soiling) and the actors'
materials; 'occlusion' asks the scenario for an occluding parked vehicle. Values are the
toolkit's choices for a clearly disturbed but realistic case of each factor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import Material
from hiyari.sensors.environment.conditions import Environment, Illumination, Soiling, SoilingSpot
from hiyari.sensors.scene.actor_shapes import ActorAppearance


@dataclass(frozen=True)
class DisturbancePreset:
    """One perception-disturbance condition."""

    name: str
    """Short name used on the command line."""
    jama_factor: str
    """The JAMA perception-disturbance factor it stands for."""
    environment: Environment = field(default_factory=Environment)
    """Weather, light and soiling."""
    appearance: ActorAppearance = field(default_factory=ActorAppearance)
    """Actor materials (clothing)."""
    sun_relative_azimuth_deg: float | None = 150.0
    """Sun azimuth relative to the ego heading, degrees (0 = straight ahead); None keeps the
    environment's network-frame azimuth."""
    occluder: bool = False
    """The scenario should park a vehicle that hides part of the target."""

    def environment_for(self, ego_heading_rad: float) -> Environment:
        """The environment with the sun placed relative to the ego heading."""
        if self.sun_relative_azimuth_deg is None:
            return self.environment
        return self.environment.with_sun_relative_to(ego_heading_rad, self.sun_relative_azimuth_deg)


_NIGHT = Environment(illumination=Illumination.NIGHT)
PRESETS: dict[str, DisturbancePreset] = {
    p.name: p
    for p in (
        DisturbancePreset("clear", "none (reference: clear day, sun behind)"),
        DisturbancePreset("rain", "space: rain, heavy (30 mm/h)", Environment(rain_mm_h=30.0)),
        DisturbancePreset("fog", "space: fog, visibility 50 m", Environment(fog_visibility_m=50.0)),
        DisturbancePreset("night", "environment: night, no street lights, headlights off", _NIGHT),
        DisturbancePreset(
            "night_headlights",
            "environment: night, ego low beams on",
            replace(_NIGHT, headlights=True),
        ),
        DisturbancePreset(
            "backlight",
            "environment: backlight (sun 5 deg above the horizon straight ahead)",
            Environment(sun_elevation_deg=5.0),
            sun_relative_azimuth_deg=0.0,
        ),
        DisturbancePreset(
            "dark_clothing",
            "target: low-reflectance clothing (black leather jacket)",
            appearance=ActorAppearance(clothing=Material.DARK_CLOTHING),
        ),
        DisturbancePreset(
            "night_headlights_dark_clothing",
            "environment x target: night, low beams, black leather (seed experiment 1-4)",
            replace(_NIGHT, headlights=True),
            ActorAppearance(clothing=Material.DARK_CLOTHING),
        ),
        DisturbancePreset(
            "soiling_uniform",
            "sensor front surface: uniform deposit (71 % one-way transmission, 3 dB two-way)",
            Environment(soiling=Soiling(uniform_transmission=math.sqrt(0.5))),
        ),
        DisturbancePreset(
            "soiling_spot",
            "sensor front surface: spot deposits (one over the boresight)",
            Environment(
                soiling=Soiling(spots=(SoilingSpot(0.0, -1.0, 4.0), SoilingSpot(-25.0, 2.0, 3.0)))
            ),
        ),
        DisturbancePreset(
            "occlusion", "surrounding objects: partial occlusion by a parked truck", occluder=True
        ),
    )
}


def disturbance_preset(name: str) -> DisturbancePreset:
    """The preset called ``name``; HiyariError lists the known ones."""
    try:
        return PRESETS[name]
    except KeyError:
        known = ", ".join(PRESETS)
        raise HiyariError(f"unknown disturbance preset {name!r} (known: {known})") from None
