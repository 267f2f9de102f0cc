"""Colours shared by the browser replay and the Foxglove markers (RGB, 0..255).

Class colours are saturated and far apart in hue so that a screenshot (or a person) can tell
the classes apart under shading. Road materials use net.materials.DISPLAY_RGB.
"""

from __future__ import annotations

import numpy as np

from hiyari.net.mesh.materials import DISPLAY_RGB, Material
from hiyari.traffic.actor_class import ActorClass

CLASS_COLORS: dict[ActorClass, tuple[int, int, int]] = {
    ActorClass.CAR: (214, 39, 40),  # red
    ActorClass.TRUCK: (31, 119, 180),  # blue
    ActorClass.BUS: (44, 160, 44),  # green
    ActorClass.MOTORCYCLE: (148, 103, 189),  # purple
    ActorClass.BICYCLE: (23, 190, 207),  # cyan
    ActorClass.PEDESTRIAN: (255, 127, 14),  # orange
}
EGO_COLOR = (255, 0, 140)  # pink
UNKNOWN_CLASS_COLOR = (160, 160, 160)

#: Perceived objects (wireframe boxes) per source; other sources get OTHER_SOURCE_COLOR.
SOURCE_COLORS: dict[str, tuple[int, int, int]] = {
    "fusion": (0, 229, 255),
    "lidar": (170, 255, 0),
    "radar": (255, 64, 255),
    "camera": (255, 255, 255),
}
OTHER_SOURCE_COLOR = (200, 200, 255)

UNKNOWN_MATERIAL_COLOR = (128, 128, 128)

#: LiDAR / radar returns coloured by ground truth: static scene and returns with no surface.
HIT_STATIC_COLOR = (150, 150, 150)
HIT_NONE_COLOR = (255, 255, 255)


def class_colors(cls: np.ndarray) -> np.ndarray:
    """(N, 3) uint8 colours for an array of ActorClass values (-1 or unknown: grey)."""
    lut = np.array([UNKNOWN_CLASS_COLOR] * 256, np.uint8)
    for c, rgb in CLASS_COLORS.items():
        lut[int(c)] = rgb
    return lut[np.asarray(cls).astype(np.int64) & 0xFF]


def source_color(source: str) -> tuple[int, int, int]:
    """Colour of one object-list source."""
    return SOURCE_COLORS.get(source, OTHER_SOURCE_COLOR)


def material_color(material: int) -> tuple[int, int, int]:
    """Colour of one Material id."""
    try:
        return DISPLAY_RGB[Material(material)]
    except (ValueError, KeyError):
        return UNKNOWN_MATERIAL_COLOR


def intensity_colors(intensity: np.ndarray) -> np.ndarray:
    """(N, 3) uint8 colours for LiDAR intensity 0..1 (viridis, clipped)."""
    from matplotlib import colormaps

    lut = (colormaps["viridis"](np.linspace(0.0, 1.0, 256))[:, :3] * 255).astype(np.uint8)
    idx = np.clip(np.nan_to_num(np.asarray(intensity, np.float64)) * 255, 0, 255).astype(np.int64)
    return lut[idx]


def signed_colors(value: np.ndarray, scale: float) -> np.ndarray:
    """(N, 3) uint8 blue (negative) - white - red (positive) over +-``scale``.

    Used for radar range rate: approaching targets (negative) blue, receding red.
    """
    v = np.clip(np.nan_to_num(np.asarray(value, np.float64)) / scale, -1.0, 1.0)
    pos, neg = np.clip(v, 0, 1), np.clip(-v, 0, 1)
    r = 255 * (1 - neg)
    g = 255 * (1 - np.abs(v))
    b = 255 * (1 - pos)
    return np.stack([r, g, b], 1).astype(np.uint8)
