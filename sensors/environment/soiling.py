"""Which sensor rays pass through soiling on the window, and how much light they keep."""

from __future__ import annotations

import math

import numpy as np

from hiyari.sensors.environment.conditions import Soiling


def soiling_mask(directions: np.ndarray, soiling: Soiling) -> tuple[np.ndarray, np.ndarray]:
    """One-way transmission (N,) and in-spot flag (N,) for unit sensor-frame ``directions``."""
    d = np.asarray(directions, dtype=np.float64)
    trans = np.full(len(d), soiling.uniform_transmission)
    spot = np.zeros(len(d), bool)
    for s in soiling.spots:
        az, el = math.radians(s.azimuth_deg), math.radians(s.elevation_deg)
        centre = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
        spot |= d @ centre >= math.cos(math.radians(s.radius_deg))
    trans[spot] *= soiling.spot_transmission
    return trans, spot
