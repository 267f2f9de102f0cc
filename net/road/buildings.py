"""Mapped buildings: footprints in network metres with a height, read from a SUMO polygon
file (polyconvert's output for an OpenStreetMap extract, or a scenario's own additional file).

A building is a ``<poly>`` whose ``type`` is ``building`` or starts with ``building.``
(polyconvert's ``--osm.keep-full-type``: ``building.yes``, ``building.apartments`` ...).
Its height in metres, from the OSM tags polyconvert keeps as ``<param>`` (``--all-attributes``):

1. ``height``: a number in metres, with an optional unit: ``12``, ``12 m``, ``12.5m``,
   ``40 ft``, ``40'`` or ``12'6"`` (feet and inches), as OSM's height key documents;
2. else ``building:levels`` x ``LEVEL_HEIGHT`` (3.0 m a storey, OSM's usual conversion);
3. else ``DEFAULT_HEIGHT`` (9 m: three storeys, a typical European city street front).

A value that is not a positive number is passed over for the next rule. Roof shapes,
``min_height`` (bridging parts) and ``building:part`` ways are not modelled: every building
is a prism from the ground to its height. Other polygons of the file (land use, water,
parking areas) are not buildings and are ignored.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from lxml import etree

from hiyari.errors import HiyariError

#: Height of one storey, m (building:levels x this).
LEVEL_HEIGHT = 3.0
#: Height of a building whose tags give none, m.
DEFAULT_HEIGHT = 9.0
_FOOT = 0.3048

_METRES = re.compile(r"^\s*(\d+(?:[.,]\d+)?)\s*(m|metres|meters)?\s*$", re.IGNORECASE)
_FEET = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*(?:ft|feet|')\s*(?:(\d+(?:\.\d+)?)\s*(?:\"|in))?\s*$")


@dataclass(frozen=True, eq=False)
class Building:
    """One building: ``outline`` (n, 2) network metres, the ring without its closing repeat;
    ``height`` m above the ground; ``rule`` the tag it came from (height, levels, default)."""

    id: str
    outline: np.ndarray
    height: float
    rule: str


def parse_height(text: str) -> float | None:
    """An OSM ``height`` value in metres (see the module docstring); None when it is none."""
    m = _METRES.match(text)
    if m:
        value = float(m.group(1).replace(",", "."))
    elif m := _FEET.match(text):
        value = (float(m.group(1)) + float(m.group(2) or 0.0) / 12.0) * _FOOT
    else:
        return None
    return value if math.isfinite(value) and value > 0 else None


def _levels(text: str) -> float | None:
    try:
        value = float(text.strip())
    except ValueError:
        return None
    return value if math.isfinite(value) and value > 0 else None


def building_height(tags: Mapping[str, str]) -> tuple[float, str]:
    """Height (m) of a building with OSM ``tags`` and the rule that gave it."""
    height = parse_height(tags["height"]) if "height" in tags else None
    if height is not None:
        return height, "height"
    levels = _levels(tags["building:levels"]) if "building:levels" in tags else None
    if levels is not None:
        return levels * LEVEL_HEIGHT, "levels"
    return DEFAULT_HEIGHT, "default"


def is_building(poly_type: str) -> bool:
    """Whether a polygon ``type`` names a building."""
    return poly_type == "building" or poly_type.startswith("building.")


def poly_path(net: str | Path) -> Path:
    """The polygon file that goes with a net: ``map.net.xml`` -> ``map.poly.xml``."""
    net = Path(net)
    name = net.name
    stem = name[: -len(".net.xml")] if name.endswith(".net.xml") else net.stem
    return net.with_name(f"{stem}.poly.xml")


def _outline(shape: str) -> np.ndarray:
    pts = np.array([[float(v) for v in p.split(",")[:2]] for p in shape.split()], dtype=float)
    if len(pts) > 1 and np.allclose(pts[0], pts[-1]):
        pts = pts[:-1]
    return pts


def read_buildings(path: str | Path) -> tuple[Building, ...]:
    """The buildings of the SUMO polygon (additional) file ``path``, in file order.

    HiyariError (one line naming the file) when it is missing, not well-formed or a shape is
    not a list of coordinates."""
    path = Path(path)
    if not path.is_file():
        raise HiyariError(f"{path}: polygon file not found")
    try:
        root = etree.parse(str(path), etree.XMLParser(huge_tree=True)).getroot()
    except etree.XMLSyntaxError as exc:
        raise HiyariError(f"{path}: polygon file is not well-formed XML: {exc.msg}") from None
    out = []
    for poly in root.iter("poly"):
        if not is_building(poly.get("type", "")):
            continue
        try:
            outline = _outline(poly.get("shape", ""))
        except ValueError:
            raise HiyariError(
                f"{path}:{poly.sourceline}: poly {poly.get('id')}: shape is not x,y pairs"
            ) from None
        if len(outline) < 3:
            continue  # a building mapped as a line or a point encloses nothing
        tags = {p.get("key", ""): p.get("value", "") for p in poly.iter("param")}
        height, rule = building_height(tags)
        out.append(Building(poly.get("id", ""), outline, height, rule))
    return tuple(out)
