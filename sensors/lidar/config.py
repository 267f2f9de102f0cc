"""LiDAR scan patterns and detection parameters, with presets for common unit sizes.

A scan is a grid of channels (elevations) x columns (azimuths) fired column by column over
one revolution (or over the horizontal field of view for non-rotating units), sweeping
clockwise seen from above. The detection threshold is given as the range at which a 10 %
Lambertian target at normal incidence in clear air returns just enough light
(``range_10pct_m``): received intensity ~ reflectance x cos(incidence) / r^2, so a target of
reflectance rho is detectable to range_10pct_m x sqrt(rho / 0.1).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from hiyari.errors import HiyariError
from hiyari.sensors.environment.atmosphere import AtmosphereModel


@dataclass(frozen=True)
class LidarConfig:
    """One LiDAR model: scan pattern, range limits, detection threshold and noise."""

    name: str
    """Preset or user name, e.g. '64ch'."""
    elevations_deg: tuple[float, ...]
    """Channel elevations in the sensor frame, degrees (positive up)."""
    columns: int
    """Azimuth samples per scan."""
    horizontal_fov_deg: float = 360.0
    """Horizontal field of view, degrees, centred on the boresight (360: rotating unit)."""
    rate_hz: float = 10.0
    """Scans per second (rotation rate)."""
    max_range_m: float = 120.0
    """Largest reported range, m."""
    min_range_m: float = 0.5
    """Smallest reported range, m (closer returns are blanked, as in real units)."""
    range_10pct_m: float = 50.0
    """Detection threshold: range of a 10 % Lambertian target at normal incidence, m."""
    range_noise_m: float = 0.02
    """Standard deviation of the range noise, m (datasheets: +-2 cm; seed PSSI: <= 10 cm)."""
    specular_lobe_deg: float = 5.0
    """Width (1 sigma) of the specular lobe of glossy materials, degrees (toolkit choice)."""
    rain_ghost_per_mm_h: float = 5e-5
    """Probability per beam and per mm/h of rain of a false return from drops (toolkit choice:
    the seed saw more ghosts with higher rain rate, divp-H section 3.5)."""
    rain_ghost_max_probability: float = 0.05
    """Cap on the per-beam drop-ghost probability."""
    rain_ghost_min_m: float = 7.0
    """Nearest range of drop ghosts, m (seed: V-b LiDAR saw drops at about 7-15 m)."""
    rain_ghost_max_m: float = 15.0
    """Farthest range of drop ghosts, m (seed)."""
    rain_ghost_intensity_span: float = 3.0
    """Drop ghosts have intensities log-uniform between the threshold and span x threshold."""
    atmosphere: AtmosphereModel = field(default_factory=AtmosphereModel)
    """Extinction coefficients for rain and fog."""

    @property
    def channels(self) -> int:
        """Number of channels (rows)."""
        return len(self.elevations_deg)

    @property
    def rays(self) -> int:
        """Rays per scan."""
        return self.channels * self.columns

    @property
    def min_intensity(self) -> float:
        """Detection threshold in intensity units (1 = white Lambertian at 1 m)."""
        return 0.1 / self.range_10pct_m**2

    def validate(self) -> LidarConfig:
        """Return self, or raise HiyariError naming the impossible parameter."""
        n = self.name
        if not self.elevations_deg:
            raise HiyariError(f"lidar {n}: needs at least one channel elevation")
        el = np.asarray(self.elevations_deg, dtype=float)
        if np.any(np.abs(el) > 90) or not np.all(np.isfinite(el)):
            raise HiyariError(f"lidar {n}: channel elevations must be within [-90, 90] degrees")
        if self.columns < 1:
            raise HiyariError(f"lidar {n}: columns must be >= 1, got {self.columns}")
        if not 0 < self.horizontal_fov_deg <= 360:
            raise HiyariError(
                f"lidar {n}: horizontal_fov_deg must be in (0, 360], got {self.horizontal_fov_deg}"
            )
        if not self.rate_hz > 0:
            raise HiyariError(f"lidar {n}: rate_hz must be positive, got {self.rate_hz}")
        if not 0 <= self.min_range_m < self.max_range_m:
            raise HiyariError(
                f"lidar {n}: need 0 <= min_range_m < max_range_m, got {self.min_range_m} and {self.max_range_m}"
            )
        if not self.range_10pct_m > 0:
            raise HiyariError(
                f"lidar {n}: range_10pct_m must be positive, got {self.range_10pct_m}"
            )
        if self.range_noise_m < 0:
            raise HiyariError(f"lidar {n}: range_noise_m must be >= 0, got {self.range_noise_m}")
        if not self.specular_lobe_deg > 0:
            raise HiyariError(
                f"lidar {n}: specular_lobe_deg must be positive, got {self.specular_lobe_deg}"
            )
        if not 0 <= self.rain_ghost_min_m < self.rain_ghost_max_m:
            raise HiyariError(f"lidar {n}: need 0 <= rain_ghost_min_m < rain_ghost_max_m")
        return self

    def with_fov(self, horizontal_fov_deg: float, columns: int | None = None) -> LidarConfig:
        """The same unit restricted to a horizontal sector, keeping the azimuth step."""
        step = self.horizontal_fov_deg / self.columns
        cols = columns if columns is not None else max(1, round(horizontal_fov_deg / step))
        return replace(self, horizontal_fov_deg=horizontal_fov_deg, columns=cols).validate()

    @staticmethod
    def preset(name: str) -> LidarConfig:
        """A preset by name; HiyariError lists the known ones."""
        try:
            return LIDAR_PRESETS[name]
        except KeyError:
            known = ", ".join(LIDAR_PRESETS)
            raise HiyariError(f"unknown lidar preset {name!r} (known: {known})") from None


def _even(lo: float, hi: float, n: int) -> tuple[float, ...]:
    return tuple(float(x) for x in np.round(np.linspace(lo, hi, n), 4))


LIDAR_PRESETS: dict[str, LidarConfig] = {
    # Modelled on a VLP-16-class unit: 16 channels over +-15 deg, 0.2 deg at 10 Hz, 100 m.
    "16ch": LidarConfig(
        "16ch",
        _even(-15.0, 15.0, 16),
        1800,
        max_range_m=100.0,
        range_10pct_m=45.0,
        range_noise_m=0.03,
    ),
    # Modelled on an HDL-32E-class unit: 32 channels over -30.67..+10.67 deg, 100 m.
    "32ch": LidarConfig(
        "32ch", _even(-30.67, 10.67, 32), 2048, max_range_m=100.0, range_10pct_m=45.0
    ),
    # Modelled on an HDL-64E-class unit: 64 channels over -24.9..+2 deg, 2048 columns, 120 m;
    # datasheet: 50 m on pavement (~10 %), 120 m on cars (~80 %), consistent with 1/r^2.
    "64ch": LidarConfig("64ch", _even(-24.9, 2.0, 64), 2048, max_range_m=120.0, range_10pct_m=50.0),
    # Modelled on a VLS-128-class unit: 128 channels over -25..+15 deg, 0.2 deg, 200 m.
    # The 64-channel pattern with the detection threshold of the seed's reference LiDAR
    # (divp-H section 3.4 C): a 6 % diffuse black-leather jacket is light-limited at 22.5 m
    # (0.1 / 29.5^2 = 0.06 / 22.9^2), while an ordinary NCAP dummy is limited by the number
    # of points on it (seed: 32.5-35 m).
    "divp-ref": LidarConfig(
        "divp-ref", _even(-24.9, 2.0, 64), 2048, max_range_m=120.0, range_10pct_m=29.5
    ),
    "128ch": LidarConfig(
        "128ch",
        _even(-25.0, 15.0, 128),
        1800,
        max_range_m=200.0,
        range_10pct_m=80.0,
        range_noise_m=0.03,
    ),
}
