"""Adhesion utilisation (grip use) and the JAMA 4.3.3.2 bands.

Grip use eps = |acting force| / (mu x normal force). JAMA Fig. 98: normal operation eps <= 30 %,
normal emergency avoidance 30-75 %, limit region (ABS) 75-100 %, beyond the limit >= 100 %.
"""

from __future__ import annotations

import numpy as np

from hiyari.units import G

BANDS = (0.30, 0.75, 1.00)
"""Upper edges of the JAMA regions, as fractions of the available friction."""
BAND_NAMES = ("normal", "emergency avoidance", "limit (ABS)", "beyond limit")

ROAD_MU = {"dry": 0.75, "wet": 0.3, "snow": 0.2, "ice": 0.1}
"""Road friction per surface. JAMA 4.3.3.3-4.3.3.6: dry 0.5-1.0 (0.75 in its Fig. 100 budget),
wet boundary 0.3 (locked wheel, < 20 mm/h rain at 100 km/h), snow and ice <= 0.2, icy 0.1-0.2."""


def band(eps: np.ndarray | float) -> np.ndarray:
    """Band index per grip use: 0 normal, 1 emergency avoidance, 2 limit, 3 beyond."""
    return np.searchsorted(np.asarray(BANDS), np.asarray(eps, dtype=np.float64), side="left")


def quasi_static_grip_use(
    speed: np.ndarray | float,
    curvature: np.ndarray | float,
    mu: np.ndarray | float,
    cross_slope: np.ndarray | float = 0.0,
    accel: np.ndarray | float = 0.0,
    lateral_disturbance: np.ndarray | float = 0.0,
) -> np.ndarray:
    """Grip use of steady cornering: |(v^2 k - g i - a_d, a_x)| / (mu g).

    speed m/s, curvature 1/m (+ left), cross_slope i = tan(bank) with + falling to the left,
    accel longitudinal m/s^2, lateral_disturbance m/s^2 (+ left, e.g. crosswind force / mass).
    JAMA eq. (4): f = V^2 / (127 R) - i is this lateral term in g.
    """
    ay = np.asarray(speed) ** 2 * np.asarray(curvature) - G * np.asarray(cross_slope)
    ay = ay - np.asarray(lateral_disturbance)
    return np.hypot(ay, np.asarray(accel)) / (np.asarray(mu) * G)
