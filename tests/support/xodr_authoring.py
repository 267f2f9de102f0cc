"""Small OpenDRIVE maps written in tests: roads with typed lanes, junctions, links."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

#: A town cross-section: (lane id -> (OpenDRIVE type, width m)), median between directions.
TOWN = {
    1: ("median", 0.5), 2: ("driving", 3.5), 3: ("border", 0.5), 4: ("sidewalk", 2.0),
    -1: ("median", 0.5), -2: ("driving", 3.5), -3: ("border", 0.5), -4: ("sidewalk", 2.0),
}  # fmt: skip
#: One driving lane per direction.
SINGLE = {1: ("driving", 3.5), -1: ("driving", 3.5)}


def opendrive() -> etree._Element:
    """An empty OpenDRIVE 1.6 document."""
    root = etree.Element("OpenDRIVE")
    etree.SubElement(root, "header", revMajor="1", revMinor="6", name="hiyari test")
    return root


def road(
    root: etree._Element,
    rid: int | str,
    start: tuple[float, float, float],
    length: float,
    lanes: dict[int, tuple[str, float]],
    shape: tuple = ("line",),
    junction: int | str = -1,
    links: tuple = (),
    lane_links: bool = False,
) -> etree._Element:
    """Append a road from ``start`` (x, y, heading rad); ``shape`` ("line",), ("arc", k) or
    ("spiral", k0, k1); ``links`` (tag, elementType, elementId, contactPoint or None);
    ``lane_links``: every lane's predecessor / successor is the lane with its own id."""
    x, y, hdg = start
    el = etree.SubElement(
        root, "road", id=str(rid), length=repr(length), junction=str(junction), name=f"r{rid}"
    )
    link = etree.SubElement(el, "link")
    for tag, kind, element, contact in links:
        attrs = {"elementType": kind, "elementId": str(element)}
        if contact:
            attrs["contactPoint"] = contact
        etree.SubElement(link, tag, attrs)
    plan = etree.SubElement(el, "planView")
    geom = etree.SubElement(
        plan, "geometry", s="0", x=repr(x), y=repr(y), hdg=repr(hdg), length=repr(length)
    )
    if shape[0] == "line":
        etree.SubElement(geom, "line")
    elif shape[0] == "arc":
        etree.SubElement(geom, "arc", curvature=repr(shape[1]))
    else:
        etree.SubElement(geom, "spiral", curvStart=repr(shape[1]), curvEnd=repr(shape[2]))
    section = etree.SubElement(etree.SubElement(el, "lanes"), "laneSection", s="0")
    left = sorted((k for k in lanes if k > 0), reverse=True)
    right = sorted((k for k in lanes if k < 0), reverse=True)
    for side, ids in (("left", left), ("center", [0]), ("right", right)):
        if not ids:
            continue
        parent = etree.SubElement(section, side)
        for lid in ids:
            kind, width = lanes.get(lid, ("none", 0.0))
            lane = etree.SubElement(parent, "lane", id=str(lid), type=kind, level="false")
            if lid == 0:
                continue
            lk = etree.SubElement(lane, "link")
            if lane_links:
                etree.SubElement(lk, "predecessor", id=str(lid))
                etree.SubElement(lk, "successor", id=str(lid))
            etree.SubElement(lane, "width", sOffset="0", a=repr(width), b="0", c="0", d="0")
    return el


def junction(
    root: etree._Element, jid: int | str, connections: list[tuple], **attrs: str
) -> etree._Element:
    """Append a junction; connections are (incoming, connecting or None, contact, lane links,
    extra attributes such as {"linkedRoad": "3"})."""
    el = etree.SubElement(root, "junction", id=str(jid), name=f"j{jid}", **attrs)
    for cid, (incoming, connecting, contact, lane_links, extra) in enumerate(connections):
        a = {"id": str(cid), "incomingRoad": str(incoming), "contactPoint": contact, **extra}
        if connecting is not None:
            a["connectingRoad"] = str(connecting)
        con = etree.SubElement(el, "connection", a)
        for f, t in lane_links:
            etree.SubElement(con, "laneLink", attrib={"from": str(f), "to": str(t)})
    return el


def write(root: etree._Element, path: Path) -> Path:
    """Write the document with an XML declaration, one element per line."""
    etree.ElementTree(root).write(
        str(path), xml_declaration=True, encoding="UTF-8", pretty_print=True
    )
    return path


def town_map(path: Path) -> Path:
    """Road 1 (x 0..100) and road 2 (x 120..220) through junction 100 (connecting road 101),
    each with a median, a driving lane, a border and a sidewalk per side (``TOWN``)."""
    root = opendrive()
    road(root, 1, (0.0, 0.0, 0.0), 100.0, TOWN, links=[("successor", "junction", 100, None)])
    road(root, 2, (120.0, 0.0, 0.0), 100.0, TOWN,
         links=[("predecessor", "junction", 100, None)])  # fmt: skip
    road(root, 101, (100.0, 0.0, 0.0), 20.0, TOWN, junction=100, lane_links=True,
         links=[("predecessor", "road", 1, "end"), ("successor", "road", 2, "start")])  # fmt: skip
    right = [(k, k) for k in TOWN if k < 0]
    left = [(k, k) for k in TOWN if k > 0]
    junction(root, 100, [(1, 101, "start", right, {}), (2, 101, "end", left, {})])
    return write(root, path)
