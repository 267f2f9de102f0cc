"""Geographic positions on an OpenDRIVE map: its header's geoReference (a PROJ string) and
offset turn WGS84 latitude / longitude into the map's x, y.

Transverse Mercator (``+proj=tmerc``, and ``+proj=utm`` with its zone) is computed by the
Krueger series to the third order in the ellipsoid's third flattening (sub-millimetre within a
UTM zone), on WGS84 / GRS80 or the ellipsoid ``+a`` / ``+rf`` / ``+b`` give. ASAM OpenDRIVE 1.6+
section 8.5: world = rotate(hdg) (map) + offset, so map = rotate(-hdg) (world - offset).
Radians in, metres out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from hiyari.errors import HiyariError

_ELLIPSOIDS = {"WGS84": (6378137.0, 298.257223563), "GRS80": (6378137.0, 298.257222101)}


@dataclass(frozen=True)
class GeoReference:
    """A Transverse Mercator projection (``a`` m, flattening ``f``, origin latitude / central
    meridian rad, scale ``k0``, false easting / northing m) and the map's offset (x, y m,
    hdg rad)."""

    a: float
    f: float
    lat_0: float
    lon_0: float
    k0: float
    x_0: float
    y_0: float
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @staticmethod
    def from_file(path: str | Path) -> GeoReference:
        """The geoReference of OpenDRIVE file ``path`` (one-line HiyariError when it has
        none or one this module does not project)."""
        root = etree.parse(str(path)).getroot()
        geo = root.find("header/geoReference")
        if geo is None or not (geo.text or "").strip():
            raise HiyariError(f"{path}: the road has no geoReference to place a GeoPosition")
        off = root.find("header/offset")
        offset = (0.0, 0.0, 0.0)
        if off is not None:
            offset = tuple(float(off.get(k, "0")) for k in ("x", "y", "hdg"))
        return parse_proj(geo.text.strip(), str(path), offset)

    def to_map(self, lat: float, lon: float) -> tuple[float, float]:
        """Map x, y (m) of WGS84 ``lat``, ``lon`` (rad)."""
        e, n = tmerc(self, lat, lon)
        _, n0 = tmerc(self, self.lat_0, self.lon_0)
        wx, wy = e + self.x_0, n - n0 + self.y_0
        ox, oy, hdg = self.offset
        dx, dy = wx - ox, wy - oy
        c, s = math.cos(hdg), math.sin(hdg)
        return dx * c + dy * s, -dx * s + dy * c


def parse_proj(text: str, where: str, offset: tuple[float, float, float]) -> GeoReference:
    """The Transverse Mercator of PROJ string ``text``."""
    p: dict[str, str] = {}
    for tok in text.split():
        if tok.startswith("+"):
            k, _, v = tok[1:].partition("=")
            p[k] = v
    proj = p.get("proj", "")
    if proj not in ("tmerc", "utm"):
        raise HiyariError(
            f"{where}: geoReference projection {proj or text!r}: hiyari projects tmerc and utm"
        )
    a, rf = _ELLIPSOIDS.get(p.get("ellps", p.get("datum", "WGS84")), _ELLIPSOIDS["WGS84"])
    if "a" in p:
        a = float(p["a"])
        rf = float(p["rf"]) if "rf" in p else (a / (a - float(p["b"])) if "b" in p else rf)
    if proj == "utm":
        zone = int(p.get("zone", "0"))
        if not 1 <= zone <= 60:
            raise HiyariError(f"{where}: geoReference utm needs +zone=1..60")
        lon_0 = math.radians(zone * 6 - 183)
        return GeoReference(a, 1 / rf, 0.0, lon_0, 0.9996, 500000.0,
                            10000000.0 if "south" in p else 0.0, offset)  # fmt: skip
    return GeoReference(
        a, 1 / rf, math.radians(float(p.get("lat_0", "0"))),
        math.radians(float(p.get("lon_0", "0"))), float(p.get("k_0", p.get("k", "1"))),
        float(p.get("x_0", "0")), float(p.get("y_0", "0")), offset,
    )  # fmt: skip


def tmerc(g: GeoReference, lat: float, lon: float) -> tuple[float, float]:
    """Transverse Mercator easting and northing (m, before false easting / northing; the
    northing from the equator) of ``lat``, ``lon`` (rad)."""
    n = g.f / (2 - g.f)
    big_a = g.a / (1 + n) * (1 + n * n / 4 + n**4 / 64)
    alpha = (n / 2 - 2 * n * n / 3 + 5 * n**3 / 16, 13 * n * n / 48 - 3 * n**3 / 5, 61 * n**3 / 240)
    c = 2 * math.sqrt(n) / (1 + n)
    t = math.sinh(math.atanh(math.sin(lat)) - c * math.atanh(c * math.sin(lat)))
    dl = lon - g.lon_0
    xi = math.atan2(t, math.cos(dl))
    eta = math.atanh(math.sin(dl) / math.sqrt(1 + t * t))
    e = eta + sum(
        al * math.cos(2 * j * xi) * math.sinh(2 * j * eta) for j, al in enumerate(alpha, 1)
    )
    nn = xi + sum(
        al * math.sin(2 * j * xi) * math.cosh(2 * j * eta) for j, al in enumerate(alpha, 1)
    )
    return g.k0 * big_a * e, g.k0 * big_a * nn
