"""Along-path disturbance profiles from the generated expressway's geometry.

Curvature comes from the expressway alignment (straight - clothoid - arc - clothoid -
straight); the cross slope is the crown on straights, ramping linearly to the full
superelevation on the arc as the expressway builder lays it (net.sumo.expressway_layout),
for the eastbound carriageway (right of the alignment, crown falling to its right edge).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.errors import HiyariError
from hiyari.net.sumo.build import ExpresswayParams
from hiyari.net.sumo.expressway_layout import make_alignment
from hiyari.risk.dynamics.vehicle import Disturbances
from hiyari.units import G


@dataclass(frozen=True)
class MotionDisturbance:
    """The JAMA 4.3 disturbances of one run."""

    mu: float = 0.75
    """Road friction (JAMA: dry 0.5-1.0, wet >= 0.3, snow / ice <= 0.2)."""
    wind_m_s: float = 0.0
    """Steady crosswind, m/s, blowing toward the outside of the curve (the adverse side)."""
    gust_m_s: float = 0.0
    """Extra gust speed on top of the steady wind, m/s (1-cos gust)."""
    gust_station_m: float = 0.0
    """Station of the gust's peak, m."""
    gust_length_m: float = 60.0
    """Length of road over which the gust acts, m."""
    rut_depth_m: float = 0.0
    """Rut depth, m (JAMA repair target on expressways: 25 mm)."""
    rut_width_m: float = 0.5
    """Rut width, m: a wheel on the flank feels g x 2 depth / width sideways (toolkit choice)."""
    rut_from_m: float = 0.0
    rut_to_m: float = 0.0
    """Stations of the rutted stretch, m."""

    def __post_init__(self) -> None:
        if not 0 < self.mu <= 1.5:
            raise HiyariError(f"road friction mu must be in (0, 1.5], got {self.mu}")
        if self.rut_width_m <= 0 or self.gust_length_m <= 0:
            raise HiyariError("rut width and gust length must be positive")


def expressway_profile(
    params: ExpresswayParams, dist: MotionDisturbance, step_m: float = 1.0
) -> Disturbances:
    """Disturbance arrays along the expressway main line, every ``step_m`` metres."""
    a = make_alignment(params)
    s = np.arange(0.0, params.length + step_m / 2, step_m)
    k = a.curvature_at(s)
    k_arc = 1.0 / params.curve_radius if params.curve_length > 0 else 0.0
    bank = np.clip(np.abs(k) / k_arc, 0.0, 1.0) if k_arc > 0 else np.zeros_like(s)
    side = 1.0 if params.curve_left else -1.0
    cross = bank * params.superelevation * side - (1 - bank) * params.cross_slope
    outward = -side  # the wind and the rut flank push toward the outside of the curve
    g = np.clip(np.abs(s - dist.gust_station_m) / (dist.gust_length_m / 2), 0.0, 1.0)
    gust = dist.gust_m_s * 0.5 * (1 + np.cos(np.pi * g))
    rut = np.where(
        (s >= dist.rut_from_m) & (s <= dist.rut_to_m), 2 * dist.rut_depth_m / dist.rut_width_m, 0.0
    )
    return Disturbances(
        s=s,
        curvature=k,
        cross_slope=cross,
        mu=np.full_like(s, dist.mu),
        wind=outward * (dist.wind_m_s + gust),
        rut_accel=outward * G * rut,
    )
