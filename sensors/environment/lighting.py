"""Light levels for the camera: sun, sky, street lights, headlights, and veiling glare.

Illuminance in lux, luminance in cd/m^2, a Lambertian surface of albedo rho under
illuminance E has luminance rho E / pi. Positions in network metres, directions unit vectors.
Shadows are not cast (toolkit simplification); a surface facing away from a source gets none.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.sensors.environment.conditions import Environment, Illumination


@dataclass(frozen=True)
class LightingModel:
    """Light sources and their levels (toolkit choices from standard photometry, noted)."""

    sun_normal_lux_day: float = 90000.0
    """Direct sunlight on a surface facing the sun, clear day, lux (typical 80-110 klx)."""
    sun_normal_lux_dusk: float = 4000.0
    """Direct sunlight near the horizon at dusk, lux (long air path: a few klx)."""
    sky_lux_day: float = 15000.0
    """Diffuse skylight on a horizontal surface, clear day, lux."""
    sky_lux_dusk: float = 300.0
    """Diffuse skylight at civil twilight, lux."""
    sky_lux_night: float = 0.05
    """Night sky glow without street lights, lux (moonless suburban sky)."""
    sky_luminance_day: float = 6000.0
    """Horizon sky luminance by day, cd/m^2 (also the fog airlight)."""
    sky_luminance_dusk: float = 60.0
    """Horizon sky luminance at dusk, cd/m^2."""
    sky_luminance_night: float = 0.005
    """Night sky luminance, cd/m^2."""
    street_light_lux_horizontal: float = 15.0
    """Road-surface illuminance under street lights, lux (CIE 115 M-class roads: 10-20 lx)."""
    street_light_lux_vertical: float = 5.0
    """Vertical illuminance on a pedestrian under street lights, lux (CIE 115 P-class: 2-5 lx)."""
    street_light_horizontal_cos: float = 0.7
    """Surfaces whose normal is within acos(0.7) = 45 deg of up get the horizontal street
    illuminance, the others the vertical one."""
    headlight_intensity_cd: float = 15000.0
    """Ego low-beam luminous intensity below the cut-off, both lamps, cd (ECE R112 class B
    requires >= 12 lx at 25 m on the 75R point, i.e. >= 7.5 kcd per lamp)."""
    headlight_above_cutoff_cd: float = 600.0
    """Low-beam intensity above the cut-off line, both lamps, cd (ECE R112 glare zone limits)."""
    headlight_cutoff_deg: float = 0.57
    """Low-beam cut-off below the horizontal, degrees (ECE R112: 1 % down)."""
    headlight_height_m: float = 0.65
    """Headlamp height above the road, m."""
    headlight_spread_deg: float = 15.0
    """Horizontal half-width (1 sigma) of the low beam, degrees (toolkit choice)."""
    oncoming_glare_cd: float = 350.0
    """Intensity of an oncoming car's low beams toward the camera, cd (ECE R112 B50L zone)."""
    glare_coefficient: float = 3.0
    """Veiling luminance L_v = k E_glare / theta^2 (theta in degrees) of the camera behind the
    windscreen; the CIE disability-glare constant of the human eye is 10 (toolkit choice)."""
    fog_layer_depth_m: float = 100.0
    """Depth of a fog layer that direct sunlight crosses, m (toolkit choice; dense fog hides
    the sun)."""
    vehicle_lamp_cd: float = 16.0
    """Luminous intensity of a vehicle's own lamps toward the camera when not day (two tail
    lamps, ECE R7: 4-17 cd each), cd; spread over the vehicle's end face."""

    def sun_lux(self, env: Environment, fog_extinction: float = 0.0) -> float:
        """Direct-sun illuminance on a surface facing the sun, lux (0 when the sun is down),
        dimmed by a fog layer of extinction ``fog_extinction`` (1/m)."""
        if not env.sun_up:
            return 0.0
        full = (
            self.sun_normal_lux_day
            if env.illumination == Illumination.DAY
            else self.sun_normal_lux_dusk
        )
        path = self.fog_layer_depth_m / math.sin(math.radians(env.sun_elevation_deg))
        return full * math.exp(-fog_extinction * path)

    def sky_lux(self, env: Environment) -> float:
        """Diffuse sky illuminance on a horizontal surface, lux."""
        return {
            Illumination.DAY: self.sky_lux_day,
            Illumination.DUSK: self.sky_lux_dusk,
            Illumination.NIGHT: self.sky_lux_night,
        }[Illumination(env.illumination)]

    def sky_luminance(self, env: Environment) -> float:
        """Horizon sky luminance, cd/m^2 (the background of misses and the fog airlight)."""
        return {
            Illumination.DAY: self.sky_luminance_day,
            Illumination.DUSK: self.sky_luminance_dusk,
            Illumination.NIGHT: self.sky_luminance_night,
        }[Illumination(env.illumination)]

    def illuminance(
        self,
        env: Environment,
        points: np.ndarray,
        normals: np.ndarray,
        lamp_xyz: np.ndarray | None = None,
        lamp_heading: float = 0.0,
        fog_extinction: float = 0.0,
    ) -> np.ndarray:
        """(N,) illuminance on surfaces at ``points`` with unit ``normals`` (N, 3), lux.

        ``lamp_xyz`` is the ground point below the ego's headlamps (None: headlights off);
        ``fog_extinction`` (1/m) dims the direct sun.
        """
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
        up = normals[:, 2]
        e = self.sky_lux(env) * 0.5 * (1.0 + up)
        if env.sun_up:
            sun = np.array(env.sun_direction())
            cos_sun = normals[:, 0] * sun[0] + normals[:, 1] * sun[1] + normals[:, 2] * sun[2]
            e = e + self.sun_lux(env, fog_extinction) * np.clip(cos_sun, 0.0, None)
        if env.street_lights and env.illumination != Illumination.DAY:
            e = e + np.where(
                up > self.street_light_horizontal_cos,
                self.street_light_lux_horizontal,
                self.street_light_lux_vertical,
            )
        if env.headlights and lamp_xyz is not None:
            e = e + self.headlight_lux(points, normals, lamp_xyz, lamp_heading)
        return e

    def headlight_lux(
        self, points: np.ndarray, normals: np.ndarray, lamp_xyz: np.ndarray, lamp_heading: float
    ) -> np.ndarray:
        """(N,) illuminance from the ego's low beams, lux (inverse square, cos incidence)."""
        lamp = np.asarray(lamp_xyz, dtype=np.float64) + [0.0, 0.0, self.headlight_height_m]
        d = points - lamp
        dist = np.maximum(np.linalg.norm(d, axis=1), 0.5)
        u = d / dist[:, None]
        bearing = np.arctan2(u[:, 1], u[:, 0]) - lamp_heading
        bearing = (bearing + np.pi) % (2 * np.pi) - np.pi
        elev = np.degrees(np.arcsin(np.clip(u[:, 2], -1.0, 1.0)))
        below = elev < -self.headlight_cutoff_deg
        intensity = np.where(below, self.headlight_intensity_cd, self.headlight_above_cutoff_cd)
        intensity = intensity * np.exp(
            -0.5 * (np.degrees(bearing) / self.headlight_spread_deg) ** 2
        )
        cos_inc = np.clip(-(normals * u).sum(1), 0.0, None)
        return intensity * cos_inc / dist**2

    def headlight_lux_on_target(
        self, distance: np.ndarray, bearing: np.ndarray, height: np.ndarray
    ) -> np.ndarray:
        """(N,) mean low-beam illuminance on an upright target facing the ego, lux.

        The part of the target below the cut-off line gets the full beam, the rest the glare
        zone's intensity; ``bearing`` is from the ego heading (rad), ``height`` the target's (m).
        """
        distance = np.maximum(np.asarray(distance, dtype=np.float64), 0.5)
        cut = self.headlight_height_m - distance * math.tan(math.radians(self.headlight_cutoff_deg))
        lit = np.clip(cut / np.maximum(height, 1e-3), 0.0, 1.0)
        intensity = lit * self.headlight_intensity_cd + (1 - lit) * self.headlight_above_cutoff_cd
        spread = np.exp(-0.5 * (np.degrees(bearing) / self.headlight_spread_deg) ** 2)
        return intensity * spread / distance**2

    def veiling_luminance(
        self, env: Environment, view_dirs: np.ndarray, glare_sources: list[tuple[np.ndarray, float]]
    ) -> np.ndarray:
        """(N,) veiling luminance from glare sources, cd/m^2 (Stiles-Holladay k E / theta^2).

        ``glare_sources`` lists (unit direction from the camera, illuminance at the lens in lux);
        the angle is floored at 1 degree (the source's own image).
        """
        view_dirs = np.asarray(view_dirs, dtype=np.float64).reshape(-1, 3)
        out = np.zeros(len(view_dirs))
        for direction, lux in glare_sources:
            cosang = np.clip(view_dirs @ direction, -1.0, 1.0)
            theta = np.maximum(np.degrees(np.arccos(cosang)), 1.0)
            out += np.where(cosang > 0, self.glare_coefficient * lux / theta**2, 0.0)
        return out

    def glare_sources(
        self,
        env: Environment,
        camera_xyz: np.ndarray,
        camera_forward: np.ndarray,
        oncoming_lamps: np.ndarray,
        fog_extinction: float = 0.0,
    ) -> list[tuple[np.ndarray, float]]:
        """Sun (when up and in front of the lens) and oncoming headlamps (not by day).

        ``oncoming_lamps`` (M, 3) are lamp positions of vehicles facing the camera.
        """
        out: list[tuple[np.ndarray, float]] = []
        if env.sun_up:
            s = np.array(env.sun_direction())
            cos_axis = float(s @ camera_forward)
            if cos_axis > 0:
                out.append((s, self.sun_lux(env, fog_extinction) * cos_axis))
        if env.oncoming_headlights and env.illumination != Illumination.DAY:
            for lamp in np.asarray(oncoming_lamps, dtype=np.float64).reshape(-1, 3):
                d = lamp - camera_xyz
                dist = float(np.linalg.norm(d))
                if dist > 1.0:
                    out.append((d / dist, self.oncoming_glare_cd / dist**2))
        return out
