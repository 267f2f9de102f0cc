"""Extinction of light and radio waves by rain and fog: the coefficients every sensor uses.

All coefficients are one-way and per metre of path. Optical extinction is in nepers per
metre (transmission ``exp(-a r)``); radar attenuation in dB per metre. Rain is described by its
rate (mm/h) through the Marshall-Palmer drop-size distribution N(D) = N0 exp(-L D) with
L = c R^e, which gives the water volume per cubic metre of air (the quantity the seed found to
drive LiDAR attenuation regardless of drop size) and the drops' optical cross-section.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from hiyari.sensors.environment.conditions import Environment


@dataclass(frozen=True)
class AtmosphereModel:
    """Rain and fog extinction coefficients (documented sources; toolkit choices marked)."""

    mp_n0: float = 8000.0
    """Marshall-Palmer intercept N0, drops per m^3 per mm of diameter (Marshall & Palmer 1948)."""
    mp_slope_coeff: float = 4.1
    """Marshall-Palmer slope L = coeff * R^exp, per mm (Marshall & Palmer 1948)."""
    mp_slope_exp: float = -0.21
    """Exponent of the Marshall-Palmer slope (Marshall & Palmer 1948)."""
    lidar_rain_db_per_m_per_mm3: float = 0.0012 / 80.0
    """LiDAR rain loss per metre of one-way path per mm^3 of drops per m^3 of air, dB. Seed
    (divp-H section 3.5, PSSI fit at 40 m): log-transmission = -0.0012 x drop volume; read here
    as dB over the two-way 80 m path (the seed leaves log base and path open: toolkit choice)."""
    optical_extinction_efficiency: float = 2.0
    """Extinction efficiency of rain drops for light (drops >> wavelength: geometric limit 2)."""
    koschmieder_contrast: float = 0.02
    """Contrast threshold that defines meteorological visibility (Koschmieder, WMO: 2 %)."""
    lidar_wavelength_nm: float = 905.0
    """LiDAR wavelength, nm (seed divp-H: DIVP's LiDAR propagation at 905 nm)."""
    radar_rain_k: float = 0.94
    """ITU-R P.838 rain coefficient k at 77 GHz, horizontal polarisation (table interpolated
    between 70 and 80 GHz), dB/km per (mm/h)^alpha."""
    radar_rain_alpha: float = 0.78
    """ITU-R P.838 rain exponent alpha at 77 GHz, horizontal polarisation."""
    radar_fog_db_per_km_per_g_m3: float = 3.0
    """ITU-R P.840 specific attenuation of fog / cloud water at 77 GHz and ~10 C, (dB/km)/(g/m^3)."""
    fog_water_coeff_g_m3: float = 0.024
    """Fog liquid water content M = (coeff / V_km)^exp g/m^3 from visibility (Eldridge 1966)."""
    fog_water_exp: float = 1.54
    """Exponent of the fog water content relation (Eldridge 1966)."""
    snow_rate_at_1km_mm_h: float = 1.0
    """Liquid-water-equivalent snowfall rate that gives 1 km visibility, mm/h; the rate scales
    as 1 / visibility (toolkit choice in line with the US NWS intensity classes: heavy snow,
    visibility <= 400 m, is about 2.5 mm/h; Rasmussen et al. 1999 show a factor 3-10 scatter)."""

    def rain_drop_volume(self, rain_mm_h: float) -> float:
        """Water volume of rain drops per volume of air, mm^3/m^3 (= N0 pi / L^4)."""
        if rain_mm_h <= 0:
            return 0.0
        lam = self.mp_slope_coeff * rain_mm_h**self.mp_slope_exp
        return self.mp_n0 * math.pi / lam**4

    def rain_optical_extinction(self, rain_mm_h: float) -> float:
        """Visible-light extinction by rain, 1/m: Q_ext x drop cross-section per m^3."""
        if rain_mm_h <= 0:
            return 0.0
        lam = self.mp_slope_coeff * rain_mm_h**self.mp_slope_exp
        area_mm2_per_m3 = self.mp_n0 * math.pi / 2.0 / lam**3  # integral of pi D^2 / 4 N(D) dD
        return self.optical_extinction_efficiency * area_mm2_per_m3 * 1e-6

    def fog_extinction(self, visibility_m: float, wavelength_nm: float = 550.0) -> float:
        """Fog extinction, 1/m: Koschmieder at 550 nm, scaled to the wavelength (Kim et al. 2001)."""
        if not math.isfinite(visibility_m):
            return 0.0
        v_km = visibility_m / 1000.0
        if v_km > 50:
            q = 1.6
        elif v_km > 6:
            q = 1.3
        elif v_km > 1:
            q = 0.16 * v_km + 0.34
        elif v_km > 0.5:
            q = v_km - 0.5
        else:
            q = 0.0
        beta = -math.log(self.koschmieder_contrast) / visibility_m
        return beta * (wavelength_nm / 550.0) ** (-q)

    def large_particle_extinction(self, visibility_m: float) -> float:
        """Extinction of snow flakes or spray drops, 1/m: Koschmieder -ln(0.02) / V, the same at
        every optical wavelength because the particles are far larger than it (0 for inf)."""
        if not math.isfinite(visibility_m):
            return 0.0
        return -math.log(self.koschmieder_contrast) / visibility_m

    def snow_rate_mm_h(self, snow_visibility_m: float) -> float:
        """Liquid-water-equivalent snowfall rate for a snow visibility, mm/h (0 for inf)."""
        if not math.isfinite(snow_visibility_m):
            return 0.0
        return self.snow_rate_at_1km_mm_h * 1000.0 / snow_visibility_m

    def _particles(self, env: Environment) -> float:
        return self.large_particle_extinction(
            env.snow_visibility_m
        ) + self.large_particle_extinction(env.spray_visibility_m)

    def lidar_extinction(self, env: Environment) -> float:
        """One-way LiDAR extinction, nepers per metre (rain per the seed's fit, fog, snow and
        spray)."""
        rain_db = self.lidar_rain_db_per_m_per_mm3 * self.rain_drop_volume(env.rain_mm_h)
        return (
            rain_db * math.log(10.0) / 10.0
            + self.fog_extinction(env.fog_visibility_m, self.lidar_wavelength_nm)
            + self._particles(env)
        )

    def visible_extinction(self, env: Environment) -> float:
        """One-way extinction of visible light, nepers per metre (rain, fog, snow, spray)."""
        return (
            self.rain_optical_extinction(env.rain_mm_h)
            + self.fog_extinction(env.fog_visibility_m)
            + self._particles(env)
        )

    def radar_attenuation_db_per_m(self, env: Environment) -> float:
        """One-way 77 GHz attenuation by rain (ITU-R P.838), fog (ITU-R P.840) and snow, dB/m.

        Snow is charged as rain of its liquid-water-equivalent rate: the wet-snow upper bound
        (dry snow attenuates less); spray drops are too few to attenuate 77 GHz measurably."""
        water_rate = env.rain_mm_h + self.snow_rate_mm_h(env.snow_visibility_m)
        rain = self.radar_rain_k * water_rate**self.radar_rain_alpha if water_rate > 0 else 0.0
        fog = 0.0
        if math.isfinite(env.fog_visibility_m):
            water = (
                self.fog_water_coeff_g_m3 / (env.fog_visibility_m / 1000.0)
            ) ** self.fog_water_exp
            fog = self.radar_fog_db_per_km_per_g_m3 * water
        return (rain + fog) / 1000.0
