"""Read an OpenStreetMap extract (.osm XML, or .osm.pbf through pyosmium) into a repaired XML
copy that netconvert and polyconvert read as OSM means it.

Real extracts carry what editors and cutting tools leave behind, and netconvert stops on some
of it (a node without a valid ``lat`` makes it load no node at all; a ``<nd ref="x">`` quits
the import). The pre-pass writes a copy (never the user's file) without:

- objects a JOSM file marks ``action="delete"`` (deleted in the editor, not yet uploaded) or
  a history extract marks ``visible="false"`` (deleted in OSM);
- nodes whose ``lat`` / ``lon`` are missing, not numbers or off the globe (the ways through
  them keep their other nodes, as for the nodes an extract cuts off);
- a node, way or relation repeating an id already read (two extracts pasted together): the
  first one is kept;
- way node references that are not integers.

The copy also makes netconvert's sidewalks follow OSM's convention: netconvert's
``--osm.sidewalks`` builds them from ``sidewalk=*`` only, so a street whose sidewalks are not
mapped gets none, while ``--sidewalks.guess`` overrides even ``sidewalk=no``. Every street of
a type that SUMO's pedestrian type map gives a sidewalk width (primary ... residential) and
that has no ``sidewalk`` / ``sidewalk:left`` / ``sidewalk:right`` / ``sidewalk:both`` tag gets
``sidewalk=both`` in the copy (a guess, not a repair: not reported per way). Bridges and
tunnels get their heights in the copy too (``hiyari.net.sumo.osm.levels``).

Each repair is one line: ``<file>:<line>: <element>: <what was done>``. What cannot be
repaired is one HiyariError line naming the file: not well-formed XML (a truncated download),
not an OSM document, no node, no ``highway=*`` way, a bounding box that misses the map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.net.sumo.osm.levels import write_levels

#: West, south, east, north in degrees (WGS84 longitude / latitude), as osmium and the OSM
#: API write a bounding box.
BBox = tuple[float, float, float, float]


@dataclass(frozen=True)
class Repair:
    """One change made to the copy: the element's source line (0 for PBF input, which has
    none), the element as written, what was done."""

    line: int
    element: str
    action: str

    def message(self, source: str | Path) -> str:
        """The one-line warning naming the user's file."""
        where = f"{source}:{self.line}" if self.line else str(source)
        return f"{where}: {self.element}: {self.action}"


@dataclass(frozen=True)
class OsmExtract:
    """What the pre-pass saw in the repaired copy: the nodes' extent (west, south, east,
    north in degrees), the number of ``highway=*`` ways and of ``building=*`` ways / relations."""

    bounds: BBox
    highways: int
    buildings: int


def is_pbf(path: str | Path) -> bool:
    """Whether ``path`` names an OSM PBF file (by its extension)."""
    return str(path).lower().endswith(".pbf")


def _tag(el: etree._Element, *attrs: str) -> str:
    shown = " ".join(f'{a}="{el.get(a)}"' for a in attrs if el.get(a) is not None)
    return f"<{el.tag}{' ' + shown if shown else ''}>"


def _coordinate(el: etree._Element, attr: str, limit: float) -> str | None:
    """Why the node's ``attr`` is unusable, or None when it is a number within ±``limit``."""
    text = el.get(attr)
    if text is None:
        return f"no {attr}"
    try:
        value = float(text)
    except ValueError:
        return f"{attr} {text!r} is not a number"
    if not (math.isfinite(value) and -limit <= value <= limit):
        return f"{attr} {text} is off the globe"
    return None


def _drop(el: etree._Element, repairs: list[Repair], action: str) -> None:
    repairs.append(Repair(el.sourceline or 0, _tag(el, "id"), action))
    el.getparent().remove(el)


def _repair(root: etree._Element) -> list[Repair]:
    repairs: list[Repair] = []
    seen: dict[str, set[str]] = {"node": set(), "way": set(), "relation": set()}
    for el in list(root):
        if el.tag not in seen:
            continue
        if el.get("action") == "delete":
            _drop(el, repairs, "deleted in the editor (action=delete): dropped")
            continue
        if el.get("visible") == "false":
            _drop(el, repairs, "deleted in OSM (visible=false): dropped")
            continue
        oid = el.get("id")
        if oid in seen[el.tag]:
            _drop(el, repairs, f"repeats {el.tag} id {oid}: dropped, the first one kept")
            continue
        seen[el.tag].add(oid)
        if el.tag == "node":
            why = _coordinate(el, "lat", 90.0) or _coordinate(el, "lon", 180.0)
            if why:
                _drop(el, repairs, f"{why}: dropped")
        elif el.tag == "way":
            for nd in el.findall("nd"):
                if not (nd.get("ref") or "").lstrip("-").isdigit():
                    way = _tag(el, "id")
                    repairs.append(Repair(nd.sourceline or 0, f"{way} {_tag(nd, 'ref')}",
                                          "not a node id: dropped from the way"))  # fmt: skip
                    el.remove(nd)
    return repairs


_SIDEWALK_KEYS = ("sidewalk", "sidewalk:left", "sidewalk:right", "sidewalk:both")


def sidewalk_types(typemap: Path) -> frozenset[str]:
    """The ``highway`` values a netconvert type map gives a ``sidewalkWidth``."""
    root = etree.parse(str(typemap)).getroot()
    return frozenset(
        t.get("id", "").partition(".")[2]
        for t in root.iter("type")
        if t.get("sidewalkWidth") and t.get("id", "").startswith("highway.")
    )


def guess_sidewalks(root: etree._Element, street_types: frozenset[str]) -> int:
    """Tag ``sidewalk=both`` on every way of ``street_types`` without a sidewalk tag (see the
    module docstring); return how many were tagged."""
    count = 0
    for way in root.iterchildren("way"):
        tags = {t.get("k"): t.get("v") for t in way.iterchildren("tag")}
        if tags.get("highway") in street_types and not any(k in tags for k in _SIDEWALK_KEYS):
            etree.SubElement(way, "tag", k="sidewalk", v="both")
            count += 1
    return count


def _parse(source: Path) -> etree._ElementTree:
    parser = etree.XMLParser(huge_tree=True, remove_blank_text=False)
    if is_pbf(source):
        return _parse_pbf(source, parser)
    try:
        return etree.parse(str(source), parser)
    except etree.XMLSyntaxError as exc:
        raise HiyariError(f"{source}: not well-formed OSM XML (truncated?): {exc.msg}") from None


def _parse_pbf(source: Path, parser: etree.XMLParser) -> etree._ElementTree:
    """The PBF file as OSM XML, through pyosmium (libosmium's reader and writer)."""
    import tempfile

    import osmium

    with tempfile.TemporaryDirectory(prefix="hiyari-net-") as tmp:
        xml = Path(tmp) / "extract.osm"
        try:
            with osmium.SimpleWriter(str(xml)) as writer:
                for obj in osmium.FileProcessor(str(source)):
                    writer.add(obj)
        except RuntimeError as exc:
            raise HiyariError(f"{source}: cannot read the OSM PBF file: {exc}") from None
        return etree.parse(str(xml), parser)


def _extract(root: etree._Element) -> OsmExtract:
    lat = [float(n.get("lat")) for n in root.iterchildren("node")]
    lon = [float(n.get("lon")) for n in root.iterchildren("node")]
    highways = sum(1 for w in root.iterchildren("way") if w.find("tag[@k='highway']") is not None)
    buildings = sum(
        1
        for el in root.iterchildren("way", "relation")
        if el.find("tag[@k='building']") is not None
    )
    return OsmExtract((min(lon), min(lat), max(lon), max(lat)), highways, buildings)


def check_bbox(source: str | Path, bbox: BBox, extract: OsmExtract) -> None:
    """HiyariError naming ``source`` when ``bbox`` is not a box or misses the map's nodes."""
    w, s, e, n = bbox
    text = ",".join(f"{v:g}" for v in bbox)
    if not (-180 <= w < e <= 180 and -90 <= s < n <= 90):
        raise HiyariError(f"--bbox {text}: not west,south,east,north in degrees with west < east "
                          "and south < north")  # fmt: skip
    mw, ms, me, mn = extract.bounds
    if e < mw or w > me or n < ms or s > mn:
        raise HiyariError(f"{source}: --bbox {text} lies outside the map (its nodes span "
                          f"{mw:.6f},{ms:.6f},{me:.6f},{mn:.6f})")  # fmt: skip


def repair_osm(
    source: str | Path, copy: str | Path, sidewalk_streets: frozenset[str] = frozenset()
) -> tuple[list[Repair], OsmExtract]:
    """Write to ``copy`` the OSM extract ``source`` (XML or PBF) as repaired XML, with
    ``sidewalk=both`` on the ``sidewalk_streets`` (highway values) that map no sidewalk and the
    heights of bridges and tunnels as node ``ele`` tags.

    Returns the repairs in file order and what the copy holds. ``source`` is only read.
    HiyariError (one line) for a missing file, malformed XML, an unreadable PBF, a document
    that is not OSM, and an extract without nodes or without a ``highway=*`` way.
    """
    source = Path(source)
    if not source.is_file():
        raise HiyariError(f"{source}: OpenStreetMap file not found")
    tree = _parse(source)
    root = tree.getroot()
    if root.tag != "osm":
        raise HiyariError(f"{source}: not an OpenStreetMap file (root element <{root.tag}>)")
    repairs = _repair(root)
    if root.find("node") is None:
        raise HiyariError(f"{source}: the extract has no node with a valid position")
    extract = _extract(root)
    if not extract.highways:
        raise HiyariError(f"{source}: the extract has no highway=* way (no road to import)")
    guess_sidewalks(root, sidewalk_streets)
    write_levels(root)
    with atomic_path(copy) as tmp:
        tree.write(str(tmp), xml_declaration=True, encoding="UTF-8")
    return sorted(repairs, key=lambda r: r.line), extract
