"""GeoPosition through the road's geoReference: Transverse Mercator against independent
closed forms (the meridian arc by quadrature, the scale across the meridian), UTM zones, the
header offset, and a TeleportAction to a GeoPosition on SUMO."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from openscenario_files import STRAIGHT, run_scenario, scenario_xml, write

from hiyari.errors import HiyariError
from hiyari.net.road.geo import parse_proj, tmerc

A, RF = 6378137.0, 298.257223563
E2 = (2 - 1 / RF) / RF


def _meridian_arc(lat: float) -> float:
    """Metres from the equator along the meridian (WGS84), by the midpoint rule."""
    phi = (np.arange(200000) + 0.5) * lat / 200000
    return float((A * (1 - E2) / (1 - E2 * np.sin(phi) ** 2) ** 1.5).sum() * lat / 200000)


def test_central_meridian_is_the_meridian_arc() -> None:
    g = parse_proj("+proj=tmerc +lat_0=0 +lon_0=11 +k=1 +x_0=0 +y_0=0 +ellps=WGS84", "t", (0, 0, 0))
    e, n = tmerc(g, math.radians(48), math.radians(11))
    assert e == pytest.approx(0.0, abs=1e-9) and n == pytest.approx(
        _meridian_arc(math.radians(48)), abs=1e-3
    )


def test_scale_across_the_meridian_and_utm() -> None:
    g = parse_proj("+proj=utm +zone=32 +ellps=WGS84 +units=m", "t", (0, 0, 0))
    lat, dl = math.radians(48), 1e-6
    e1, _ = tmerc(g, lat, g.lon_0 + dl)
    nu = A / math.sqrt(1 - E2 * math.sin(lat) ** 2)  # prime vertical radius
    assert e1 == pytest.approx(0.9996 * nu * math.cos(lat) * dl, rel=1e-6)
    assert g.lon_0 == pytest.approx(math.radians(9)) and g.x_0 == 500000
    assert parse_proj("+proj=utm +zone=32 +south", "t", (0, 0, 0)).y_0 == 10000000
    with pytest.raises(HiyariError, match="hiyari projects tmerc and utm"):
        parse_proj("+proj=lcc +lat_1=45", "t.xodr", (0, 0, 0))


def test_teleport_to_a_geo_position(tmp_path: Path) -> None:
    text = STRAIGHT.read_text()
    header = '<geoReference><![CDATA[+proj=tmerc +lat_0=48 +lon_0=11 +k=1 +x_0=0 +y_0=0 +ellps=WGS84]]></geoReference><offset x="-100" y="5" z="0" hdg="0"/>'
    text = text.replace("</header>", header + "</header>", 1)
    assert header in text
    xodr = write(tmp_path / "geo_straight.xodr", text)
    g = parse_proj(
        "+proj=tmerc +lat_0=48 +lon_0=11 +k=1 +x_0=0 +y_0=0 +ellps=WGS84", "t", (-100, 5, 0)
    )
    # 48 N, 11.001 E: about 74.6 m east of the origin; the map is 100 m west, 5 m north of it
    lat, lon = math.radians(48.0), math.radians(11.001)
    x, y = g.to_map(lat, lon)
    init = """<Private entityRef="Ego"><PrivateAction><TeleportAction><Position>
<GeoPosition latitudeDeg="48.0" longitudeDeg="11.001"/></Position></TeleportAction></PrivateAction></Private>"""
    engine, _ = run_scenario(
        write(tmp_path / "g.xosc", scenario_xml({"Ego": ""}, init, road=xodr)), tmp_path, until=0.5
    )
    a = engine.actors["Ego"]
    assert (a.x, a.y) == pytest.approx((x, y), abs=1e-6) and x == pytest.approx(100 + 74.6, abs=0.2)
