"""The environment every sensor shares: rain, fog, light, sun and soiling of the sensor windows.

One Environment object is passed to every sensor of a frame. Units: rain rate in mm/h, fog as
meteorological visibility in metres (the distance at which a black target's contrast falls to
2 %), sun angles in degrees (azimuth counter-clockwise from network +x, elevation above the
horizon). Factor names follow the JAMA perception-disturbance tree (jama-B section 9, jama-C).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from enum import StrEnum

from hiyari.errors import HiyariError

SENSOR_KINDS = ("lidar", "radar", "camera")
"""Sensor kinds an environment can address one by one (window soiling)."""


class Illumination(StrEnum):
    """Time of day as far as light levels go (see lighting.LightingModel for the lux)."""

    DAY = "day"
    DUSK = "dusk"
    NIGHT = "night"


@dataclass(frozen=True)
class SoilingSpot:
    """One deposit on a sensor window, as a disc of directions in the sensor frame (degrees)."""

    azimuth_deg: float
    elevation_deg: float
    radius_deg: float


@dataclass(frozen=True)
class Soiling:
    """Deposits on the sensor windows (JAMA: 'sensor front surface, uniform / spot').

    A uniform layer only attenuates (misses); spots attenuate and refract the rays that pass
    through them (misses and ghosts), as jama-C section 3.2 classifies them.
    """

    uniform_transmission: float = 1.0
    """One-way power transmission of a layer covering the whole window (1 = clean)."""
    spots: tuple[SoilingSpot, ...] = ()
    """Discrete deposits (mud, droplets, insects) on the window."""
    spot_transmission: float = 0.05
    """One-way power transmission through a spot (toolkit choice: dried mud is nearly opaque)."""
    spot_deflection_deg: float = 3.0
    """Standard deviation of the refraction a spot gives a ray passing through it, degrees
    (toolkit choice; jama-C: spots act through surface attenuation, refraction and delay)."""

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:
        """HiyariError for transmissions outside (0, 1] or non-positive spot radii."""
        if not 0.0 < self.uniform_transmission <= 1.0:
            raise HiyariError(
                f"soiling uniform_transmission must be in (0, 1], got {self.uniform_transmission}"
            )
        if not 0.0 <= self.spot_transmission <= 1.0:
            raise HiyariError(
                f"soiling spot_transmission must be in [0, 1], got {self.spot_transmission}"
            )
        if self.spot_deflection_deg < 0:
            raise HiyariError(
                f"soiling spot_deflection_deg must be >= 0, got {self.spot_deflection_deg}"
            )
        for s in self.spots:
            if not s.radius_deg > 0:
                raise HiyariError(f"soiling spot radius must be positive, got {s.radius_deg} deg")


@dataclass(frozen=True)
class Environment:
    """Weather, light and soiling for one frame, shared by LiDAR, radar and camera."""

    rain_mm_h: float = 0.0
    """Rain rate, mm/h (seed rainfall facility: 20-300 mm/h)."""
    fog_visibility_m: float = math.inf
    """Meteorological visibility in fog, m (inf = no fog)."""
    illumination: Illumination = Illumination.DAY
    """Day, dusk or night light levels."""
    street_lights: bool = False
    """Street lighting on (matters at dusk and night; seed night-NCAP street light)."""
    headlights: bool = False
    """Ego low-beam headlights on (seed night experiments 1-2 to 1-5)."""
    oncoming_headlights: bool = True
    """Other vehicles' headlights are on whenever it is not day (glare for the camera)."""
    sun_azimuth_deg: float = 135.0
    """Sun azimuth, degrees counter-clockwise from network +x."""
    sun_elevation_deg: float = 45.0
    """Sun elevation above the horizon, degrees (ignored at night)."""
    soiling: Soiling = field(default_factory=Soiling)
    """Deposits on the sensor windows, for every sensor without its own entry in
    ``sensor_soiling``."""
    sensor_soiling: tuple[tuple[str, Soiling], ...] = ()
    """Deposits on one sensor's window, as (sensor kind: 'lidar' / 'radar' / 'camera', soiling)
    pairs (JAMA: dirt on one sensor front while the others stay clean)."""
    snow_visibility_m: float = math.inf
    """Meteorological visibility in falling snow, m (inf = no snow; JAMA rows grade snow by
    visibility: 'reduced' vs 'poor')."""
    spray_visibility_m: float = math.inf
    """Visibility through the spray kicked up by traffic on a wet road, m (inf = none; JAMA
    'rain / snow, kicked up': partial poor visibility)."""

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> Environment:
        """Return self, or raise HiyariError naming the impossible parameter."""
        if not (self.rain_mm_h >= 0 and math.isfinite(self.rain_mm_h)):
            raise HiyariError(f"rain_mm_h must be a finite rate >= 0 mm/h, got {self.rain_mm_h}")
        if self.rain_mm_h > 500:
            raise HiyariError(
                f"rain_mm_h {self.rain_mm_h} is beyond any recorded rain (max 500 mm/h)"
            )
        for name in ("fog_visibility_m", "snow_visibility_m", "spray_visibility_m"):
            if not getattr(self, name) > 0:
                raise HiyariError(f"{name} must be positive, got {getattr(self, name)}")
        for kind, soiling in self.sensor_soiling:
            if kind not in SENSOR_KINDS:
                raise HiyariError(
                    f"sensor_soiling names unknown sensor {kind!r} (known: {', '.join(SENSOR_KINDS)})"
                )
            soiling.validate()
        if not -90 <= self.sun_elevation_deg <= 90:
            raise HiyariError(
                f"sun_elevation_deg must be in [-90, 90], got {self.sun_elevation_deg}"
            )
        try:
            Illumination(self.illumination)
        except ValueError:
            known = ", ".join(i.value for i in Illumination)
            raise HiyariError(
                f"illumination {self.illumination!r} unknown (known: {known})"
            ) from None
        self.soiling.validate()
        return self

    def for_sensor(self, kind: str) -> Environment:
        """The environment one sensor sees: its own window soiling when it has one."""
        own = dict(self.sensor_soiling).get(kind)
        return self if own is None else replace(self, soiling=own, sensor_soiling=())

    @property
    def sun_up(self) -> bool:
        """True when direct sunlight reaches the scene."""
        return self.illumination != Illumination.NIGHT and self.sun_elevation_deg > 0

    def with_sun_relative_to(self, heading_rad: float, relative_azimuth_deg: float) -> Environment:
        """A copy with the sun at ``relative_azimuth_deg`` from a heading (0 = straight ahead)."""
        az = math.degrees(heading_rad) + relative_azimuth_deg
        return replace(self, sun_azimuth_deg=(az + 180.0) % 360.0 - 180.0)

    def sun_direction(self) -> tuple[float, float, float]:
        """Unit vector toward the sun in the network frame."""
        az, el = math.radians(self.sun_azimuth_deg), math.radians(self.sun_elevation_deg)
        return (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
