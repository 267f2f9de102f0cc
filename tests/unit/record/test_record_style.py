"""The recorder's colours: its viridis table is matplotlib's, byte for byte."""

from __future__ import annotations

import numpy as np
from matplotlib import colormaps

from hiyari.bridge.record.style import intensity_colors


def test_intensity_colours_are_matplotlibs_viridis():
    lut = (colormaps["viridis"](np.linspace(0.0, 1.0, 256))[:, :3] * 255).astype(np.uint8)
    x = np.concatenate([np.linspace(-0.2, 1.2, 10001), [np.nan]])
    want = lut[np.clip(np.nan_to_num(x) * 255, 0, 255).astype(int)]
    assert np.array_equal(intensity_colors(x), want)
