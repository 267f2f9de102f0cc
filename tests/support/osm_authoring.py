"""Small OpenStreetMap files written in tests: nodes placed in local metres, tagged ways.

Tagged as OSM maps them (highway=*, sidewalk=*, highway=traffic_signals on a junction node,
highway=crossing on a node of the street, building=* closed ways with height or
building:levels), so the importer is exercised on OSM's conventions, not on a private dialect.
"""

from __future__ import annotations

import math
from pathlib import Path

from lxml import etree

#: Metres per degree of latitude (spherical Earth of SUMO's projection radius, close enough
#: for placing nodes; the tests measure distances in the converted net, not here).
M_PER_DEG = 6378137.0 * math.pi / 180.0


class OsmDoc:
    """An OSM XML document under construction; positions in metres east / north of
    (``lat0``, ``lon0``)."""

    def __init__(self, lat0: float = 52.5200, lon0: float = 13.4050) -> None:
        self.lat0, self.lon0 = lat0, lon0
        self.root = etree.Element("osm", version="0.6", generator="hiyari tests")
        self._next = 1
        self.ids: dict[str, int] = {}  # named elements of the layout functions below

    def latlon(self, x: float, y: float) -> tuple[float, float]:
        """Latitude and longitude of the point ``x`` m east, ``y`` m north of the origin."""
        lat = self.lat0 + y / M_PER_DEG
        lon = self.lon0 + x / (M_PER_DEG * math.cos(math.radians(self.lat0)))
        return lat, lon

    def node(self, x: float, y: float, **tags: str) -> int:
        """Add a node at (``x``, ``y``) m; return its id."""
        nid = self._next
        self._next += 1
        lat, lon = self.latlon(x, y)
        el = etree.SubElement(
            self.root, "node", id=str(nid), version="1", lat=f"{lat:.7f}", lon=f"{lon:.7f}"
        )
        _tags(el, tags)
        return nid

    def way(self, nodes: list[int], **tags: str) -> int:
        """Add a way through ``nodes``; tag keys with ':' are written with '__' (``building__levels``)."""
        wid = self._next
        self._next += 1
        el = etree.SubElement(self.root, "way", id=str(wid), version="1")
        for n in nodes:
            etree.SubElement(el, "nd", ref=str(n))
        _tags(el, tags)
        return wid

    def building(self, x0: float, y0: float, x1: float, y1: float, **tags: str) -> int:
        """A closed building way around the box (x0, y0)-(x1, y1) m, ``building=yes`` unless
        given."""
        ring = [self.node(x0, y0), self.node(x1, y0), self.node(x1, y1), self.node(x0, y1)]
        return self.way([*ring, ring[0]], **{"building": "yes", **tags})

    def write(self, path: str | Path) -> Path:
        """Write the document and return its path."""
        etree.ElementTree(self.root).write(
            str(path), xml_declaration=True, encoding="UTF-8", pretty_print=True
        )
        return Path(path)


def _tags(el: etree._Element, tags: dict[str, str]) -> None:
    for k, v in tags.items():
        etree.SubElement(el, "tag", k=k.replace("__", ":"), v=v)


def town(doc: OsmDoc | None = None) -> OsmDoc:
    """A few city blocks (see the layout below), every way tagged as OSM would map it.

    Streets (x east, y north, metres)::

        y=100  A-------B-------C        North Street: residential, maxspeed=30, sidewalk=both
               |       |       |
        y=0    D---x---E-------F        Main Street: primary, lanes=4, maxspeed=50, sidewalk=both
               |       |       |        E: highway=traffic_signals; x: a zebra crossing node
        y=-100 G-------H-------I        South Street: residential, no sidewalk tag (guessed)
            x=-100    x=0    x=100

    North-south streets are residential with ``sidewalk=both``, except F-I: ``sidewalk=no``.
    The zebra crossing node sits on D-E at x = -50. Two buildings: ``height=12 m`` on the
    block x 20..60, y 20..60 and ``building:levels=5`` on x -60..-20, y -60..-20. ``ids``
    names the elements: the grid nodes "A".."I", "crossing", the streets "north", "main",
    "south", "F-I" and the buildings "tall" (height) and "levels".
    """
    doc = doc or OsmDoc()
    names = {"A": (-100, 100), "B": (0, 100), "C": (100, 100), "D": (-100, 0), "E": (0, 0),
             "F": (100, 0), "G": (-100, -100), "H": (0, -100), "I": (100, -100)}  # fmt: skip
    ids = doc.ids
    for name, (x, y) in names.items():
        tags = {"highway": "traffic_signals"} if name == "E" else {}
        ids[name] = doc.node(float(x), float(y), **tags)
    ids["crossing"] = doc.node(-50.0, 0.0, highway="crossing", crossing="zebra")
    n = {k: ids[k] for k in names}
    ids["north"] = doc.way([n["A"], n["B"], n["C"]], highway="residential",
                           name="North Street", maxspeed="30", sidewalk="both")  # fmt: skip
    ids["main"] = doc.way([n["D"], ids["crossing"], n["E"], n["F"]], highway="primary",
                          name="Main Street", lanes="4", maxspeed="50", sidewalk="both")  # fmt: skip
    ids["south"] = doc.way([n["G"], n["H"], n["I"]], highway="residential", name="South Street")
    for a, b in (("A", "D"), ("D", "G"), ("B", "E"), ("E", "H"), ("C", "F"), ("F", "I")):
        sidewalk = "no" if (a, b) == ("F", "I") else "both"
        ids[f"{a}-{b}"] = doc.way([n[a], n[b]], highway="residential", sidewalk=sidewalk)
    ids["tall"] = doc.building(20.0, 20.0, 60.0, 60.0, height="12 m")
    ids["levels"] = doc.building(-60.0, -60.0, -20.0, -20.0, building__levels="5")
    return doc


def bridge_loop(doc: OsmDoc | None = None, **bridge_tags: str) -> OsmDoc:
    """A secondary road on a bridge over a residential street, closed into one loop (an
    extract's road that leads nowhere is not imported)::

        y=150              N ---- NE street ---- E' (150, 0) is E
                           |
        y=20               n  bridge: bridge=yes, layer=1 (or ``bridge_tags``)
        y=0    W ------- (over) -------- E      Under Street: residential, on the ground
        y=-20              s
                           |
        y=-150             S ---- SW street ---- W
            x=-150       x=0          x=150

    The bridge way is s -> n (two nodes: nothing on it between its ends); "south" S -> s and
    "north" n -> N are its approach roads. ``ids``: nodes "W", "E", "S", "N", "s", "n"; ways
    "under", "south", "bridge", "north".
    """
    doc = doc or OsmDoc()
    ids = doc.ids
    for name, (x, y) in {"W": (-150, 0), "E": (150, 0), "S": (0, -150), "N": (0, 150),
                         "s": (0, -20), "n": (0, 20)}.items():  # fmt: skip
        ids[name] = doc.node(float(x), float(y))
    mid = [doc.node(-50.0, 0.0), doc.node(50.0, 0.0)]  # Under Street's shape, clear of x = 0
    ids["under"] = doc.way([ids["W"], *mid, ids["E"]], highway="residential", name="Under")
    ids["south"] = doc.way([ids["S"], ids["s"]], highway="secondary", name="South")
    tags = bridge_tags or {"bridge": "yes", "layer": "1"}
    ids["bridge"] = doc.way([ids["s"], ids["n"]], highway="secondary", name="Bridge", **tags)
    ids["north"] = doc.way([ids["n"], ids["N"]], highway="secondary", name="North")
    doc.way([ids["E"], ids["N"]], highway="residential", name="NE")
    doc.way([ids["S"], ids["W"]], highway="residential", name="SW")
    return doc


def staggered_junction(doc: OsmDoc | None = None) -> OsmDoc:
    """A secondary road with a 10 m jog where two residential side roads meet it, one from
    the north at A, one from the south at B (a staggered junction; netconvert joins A and B,
    8 m apart on the map, into one junction)::

        y=150       N
                    |
        y=0   W --- A
                     \\
        y=-8          B --- E      Main Street: W (-150, 0) A (0, 0) B (6, -8) E (150, -8)
                      |
        y=-150        S

    Two residential streets close the loop: W -> N and S -> E. ``ids``: nodes "A", "B";
    way "main".
    """
    doc = doc or OsmDoc()
    ids = doc.ids
    for name, (x, y) in {"W": (-150, 0), "A": (0, 0), "B": (6, -8), "E": (150, -8),
                         "N": (0, 150), "S": (6, -150)}.items():  # fmt: skip
        ids[name] = doc.node(float(x), float(y))
    ids["main"] = doc.way([ids[k] for k in "WABE"], highway="secondary", name="Main Street")
    doc.way([ids["N"], ids["A"]], highway="residential", name="North Street")
    doc.way([ids["B"], ids["S"]], highway="residential", name="South Street")
    doc.way([ids["W"], ids["N"]], highway="residential")
    doc.way([ids["S"], ids["E"]], highway="residential")
    return doc


def dead_start(doc: OsmDoc | None = None) -> OsmDoc:
    """A two-way street N -> X -> B that goes on one-way from B to S, with a mapped crossing
    node X 3 m before B: netconvert leaves a road piece B -> X some 0.2 m long whose car lane
    nothing leads into (no street other than the one-way one meets at B)::

        y=100   N ------------ (Loop, residential, two-way) ---- W (-100, 0) -- S
        y=3     X  highway=crossing
        y=0     B
        y=-100  S  (B -> S: oneway=yes)

    ``ids``: nodes "B", "X"; ways "two-way", "one-way".
    """
    doc = doc or OsmDoc()
    ids = doc.ids
    for name, (x, y) in {"S": (0, -100), "B": (0, 0), "N": (0, 100), "W": (-100, 0)}.items():
        ids[name] = doc.node(float(x), float(y))
    ids["X"] = doc.node(0.0, 3.0, highway="crossing")
    ids["two-way"] = doc.way([ids["N"], ids["X"], ids["B"]], highway="residential")
    ids["one-way"] = doc.way([ids["B"], ids["S"]], highway="residential", oneway="yes")
    doc.way([ids["S"], ids["W"], ids["N"]], highway="residential", name="Loop")
    return doc


def crossing_at_junction(doc: OsmDoc | None = None) -> OsmDoc:
    """A mapped zebra crossing (``highway=crossing``) on the node J where a residential side
    street without sidewalks (``sidewalk=no``) crosses Main Street (secondary, sidewalks on
    both sides): netconvert puts the crossings over Main Street's two legs inside junction J,
    4 m wide, where the side street's straight-on cars pass::

        y=150          N
                       |
        y=0    W ----- J ----- E     Main Street
                       |
        y=-150         S             loop: N -> W, S -> E (residential, no sidewalks)

    ``ids``: node "J"; ways "main", "side".
    """
    doc = doc or OsmDoc()
    ids = doc.ids
    ids["J"] = doc.node(0.0, 0.0, highway="crossing", crossing="zebra")
    for name, (x, y) in {"N": (0, 150), "S": (0, -150), "W": (-150, 0), "E": (150, 0)}.items():
        ids[name] = doc.node(float(x), float(y))
    ids["main"] = doc.way([ids["W"], ids["J"], ids["E"]], highway="secondary",
                          name="Main Street", sidewalk="both")  # fmt: skip
    ids["side"] = doc.way([ids["N"], ids["J"], ids["S"]], highway="residential", sidewalk="no")
    doc.way([ids["N"], ids["W"]], highway="residential", sidewalk="no")
    doc.way([ids["S"], ids["E"]], highway="residential", sidewalk="no")
    return doc
