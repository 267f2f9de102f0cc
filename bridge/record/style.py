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


#: matplotlib's viridis as 256 RGB bytes (its own 256-entry table, scaled and truncated as
#: ``(colormaps["viridis"](np.linspace(0, 1, 256))[:, :3] * 255).astype(uint8)``): the recorder
#: colours point clouds without importing the plotting library.
_VIRIDIS = np.frombuffer(
    bytes.fromhex(
        "44015444025544035745055845065a45085b46095c460b5e460c5f460e61470f624711634712654714664715"
        "6747166947186a48196b481a6c481c6e481d6f481e7048207148217248227348237447257547267647277747"
        "2878472a79472b7a472c7b462d7c462f7c46307d46317e45327f45347f453580453681443781443982433a83"
        "433b83433c84423d84423e854240854141864142864043874044873f45873f47883e48883e49893d4a893d4b"
        "893d4c893c4d8a3c4e8a3b508a3b518a3a528b3a538b39548b39558b38568b38578c37588c37598c365a8c36"
        "5b8c355c8c355d8c345e8d345f8d33608d33618d32628d32638d31648d31658d31668d30678d30688d2f698d"
        "2f6a8d2e6b8e2e6c8e2e6d8e2d6e8e2d6f8e2c708e2c718e2c728e2b738e2b748e2a758e2a768e2a778e2978"
        "8e29798e287a8e287a8e287b8e277c8e277d8e277e8e267f8e26808e26818e25828e25838d24848d24858d24"
        "868d23878d23888d23898d22898d228a8d228b8d218c8d218d8c218e8c208f8c20908c20918c1f928c1f938b"
        "1f948b1f958b1f968b1e978a1e988a1e998a1e998a1e9a891e9b891e9c891e9d881e9e881e9f881ea0871fa1"
        "871fa2861fa38620a48520a58521a68521a78422a78423a88323a98224aa8225ab8126ac8127ad8028ae7f29"
        "af7f2ab07e2bb17d2cb17d2eb27c2fb37b30b47a32b57a33b67935b77836b87738b97639b9763bba753dbb74"
        "3ebc7340bd7242be7144be7045bf6f47c06e49c16d4bc26c4dc26b4fc36951c46853c56755c66657c66559c7"
        "645bc8625ec96160c96062ca5f64cb5d67cc5c69cc5b6bcd596dce5870ce5672cf5574d05477d05279d1517c"
        "d24f7ed24e81d34c83d34b86d44988d5478bd5468dd64490d64392d74195d73f97d83e9ad83c9dd93a9fd938"
        "a2da37a5da35a7db33aadb32addc30afdc2eb2dd2cb5dd2bb7dd29bade27bdde26bfdf24c2df22c5df21c7e0"
        "1fcae01ecde01dcfe11cd2e11bd4e11ad7e219dae218dce218dfe318e1e318e4e318e7e419e9e419ece41aee"
        "e51bf1e51cf3e51ef6e61ff8e621fae622fde724"
    ),
    np.uint8,
).reshape(256, 3)


def intensity_colors(intensity: np.ndarray) -> np.ndarray:
    """(N, 3) uint8 colours for LiDAR intensity 0..1 (viridis, clipped)."""
    idx = np.clip(np.nan_to_num(np.asarray(intensity, np.float64)) * 255, 0, 255).astype(np.int64)
    return _VIRIDIS[idx]


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
