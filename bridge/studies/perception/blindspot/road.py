"""The five-lane road of the blind-spot scenarios: straight, left or right curve.

One OpenDRIVE road "1" of five 3.5 m driving lanes (ids -1..-5, traffic along +s), a line or
an arc of radius RADIUS_M from (0, 0) heading +x. The ego drives in the middle lane (-3), so
every grid position (two lanes either side) exists. Poses on it are computed here too, so the
ray-cast check places the actors exactly where the scenario's Init puts them.
"""

from __future__ import annotations

import math
from pathlib import Path

from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.bridge.studies.perception.blindspot.catalogue import Geometry

LANE_WIDTH_M = 3.5
LANES = 5
EGO_LANE = -3
RADIUS_M = 280.0
"""Curve radius, m: the Japanese road-structure minimum for an 80 km/h design speed (the
JAMA text gives no blind-spot geometry; toolkit choice)."""
LENGTH_M = 900.0


def curvature(geometry: Geometry) -> float:
    """Road curvature, 1/m (+ left)."""
    return {Geometry.STRAIGHT: 0.0, Geometry.LEFT: 1 / RADIUS_M, Geometry.RIGHT: -1 / RADIUS_M}[
        geometry
    ]


def lane_id(offset: int) -> int:
    """OpenDRIVE lane id of the lane ``offset`` lanes left of the ego's."""
    return EGO_LANE + offset


def pose(geometry: Geometry, lane: int, s: float) -> tuple[float, float, float]:
    """(x, y, heading) of lane ``lane``'s centre at station ``s`` (m, m, rad)."""
    k = curvature(geometry)
    if k == 0.0:
        x, y, h = s, 0.0, 0.0
    else:
        h = k * s
        x, y = math.sin(h) / k, (1 - math.cos(h)) / k
    t = -(abs(lane) - 0.5) * LANE_WIDTH_M
    return x - t * math.sin(h), y + t * math.cos(h), h


def write_road(geometry: Geometry, path: Path) -> Path:
    """Write the OpenDRIVE file of ``geometry`` to ``path``."""
    root = etree.Element("OpenDRIVE")
    etree.SubElement(
        root, "header", revMajor="1", revMinor="6", name=f"hiyari blind spots {geometry}"
    )
    road = etree.SubElement(root, "road", id="1", length=repr(LENGTH_M), junction="-1", name="r1")
    etree.SubElement(road, "link")
    plan = etree.SubElement(road, "planView")
    geom = etree.SubElement(plan, "geometry", s="0", x="0", y="0", hdg="0", length=repr(LENGTH_M))
    k = curvature(geometry)
    if k == 0.0:
        etree.SubElement(geom, "line")
    else:
        etree.SubElement(geom, "arc", curvature=repr(k))
    section = etree.SubElement(etree.SubElement(road, "lanes"), "laneSection", s="0")
    etree.SubElement(
        etree.SubElement(section, "center"), "lane", id="0", type="none", level="false"
    )
    right = etree.SubElement(section, "right")
    for i in range(1, LANES + 1):
        lane = etree.SubElement(right, "lane", id=str(-i), type="driving", level="false")
        etree.SubElement(lane, "link")
        etree.SubElement(lane, "width", sOffset="0", a=repr(LANE_WIDTH_M), b="0", c="0", d="0")
    with atomic_path(path) as tmp:
        etree.ElementTree(root).write(
            str(tmp), xml_declaration=True, encoding="UTF-8", pretty_print=True
        )
    return path
