"""Physical constants and unit conversions: the one place for them.

Inside the toolkit everything is SI (metres, seconds, m/s, m/s^2, radians); km/h, g and
degrees appear only at the edges (files, command line, plots) and are converted here.
"""

from __future__ import annotations

import numpy as np

#: Standard gravity, m/s^2 (the value JAMA's C&C driver model uses: 0.774 g = 7.59 m/s^2).
G = 9.81
#: km/h per m/s.
KMH_PER_MPS = 3.6


def kmh_to_mps(v_kmh: float | np.ndarray) -> float | np.ndarray:
    """Speed in km/h -> m/s."""
    return v_kmh / KMH_PER_MPS


def mps_to_kmh(v_mps: float | np.ndarray) -> float | np.ndarray:
    """Speed in m/s -> km/h."""
    return v_mps * KMH_PER_MPS


def g_to_mps2(a_g: float | np.ndarray) -> float | np.ndarray:
    """Acceleration in g -> m/s^2."""
    return a_g * G
