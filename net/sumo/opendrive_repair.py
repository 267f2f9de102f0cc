"""Repair valid OpenDRIVE that netconvert refuses, on a copy, naming every change.

Other OpenDRIVE tools (esmini, CARLA, RoadRunner exports) read these constructs; netconvert
stops on them. The pre-pass rewrites a temporary copy (never the user's file) so that
netconvert reads what the author meant:

- a junction ``<connection>`` without ``connectingRoad`` (the roads of a direct junction,
  ``<junction type="direct">``, link through ``linkedRoad``): the linked road becomes the
  connection's target, an ordinary road-to-road connection at the junction's node; a
  connection that names no road at all is dropped;
- ``<junction type="direct">``: netconvert's own junction type (the connections above carry
  the links; netconvert reads them keyed on the incoming road only, so the import then makes
  the net's links exactly the file's laneLinks, ``hiyari.net.sumo.direct_junctions``);
- a road named as a junction's ``connectingRoad`` but marked ``junction="-1"``: a connecting
  road of that junction (read as an ordinary road, it would cross the junction's other
  connecting roads with no junction logic between them);
- ``<arc curvature="0">`` (or one too flat to bend the road by ``FLAT`` metres over its
  length): a ``<line/>`` (the same geometry; netconvert divides by the curvature);
- a ``<spiral>`` whose start and end curvatures (nearly) agree, so that it departs from an
  arc by less than ``FLAT`` metres: an ``<arc>`` of the mean curvature (netconvert's spiral
  code runs out of memory on them);
- ``<signal type="">`` (or no type): dropped (a signal of no type regulates nothing).

Each repair is one line: ``<file>:<line>: <element>: <what was done>``.
"""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.xml_repair import Repair
from hiyari.xml_repair import tag as _tag

#: Largest lateral departure, m, below which a curve is read as the simpler one (arc as line,
#: spiral as arc): far below any lane-width or survey precision.
FLAT = 1e-4


def _connections(root: etree._Element) -> list[Repair]:
    repairs = []
    for junction in root.iter("junction"):
        for con in junction.findall("connection"):
            if con.get("connectingRoad"):
                continue
            tag = _tag(con, "id", "incomingRoad", "linkedRoad")
            linked = con.get("linkedRoad")
            if linked:
                con.set("connectingRoad", linked)
                del con.attrib["linkedRoad"]
                action = f"no connectingRoad: connected to linked road {linked} directly"
            else:
                junction.remove(con)
                action = "no connectingRoad and no linkedRoad: dropped"
            repairs.append(
                Repair(con.sourceline or 0, f"junction {junction.get('id')} {tag}", action)
            )
    return repairs


def _unmarked_connecting_roads(root: etree._Element) -> list[Repair]:
    """Roads a (non-direct) junction connects through that do not say they belong to it."""
    roads = {r.get("id"): r for r in root.iter("road")}
    repairs = []
    for junction in root.iter("junction"):
        if junction.get("type") == "direct":
            continue
        for con in junction.findall("connection"):
            road = roads.get(con.get("connectingRoad"))
            if road is None or road.get("junction", "-1") != "-1":
                continue
            tag = _tag(road, "id", "junction")
            road.set("junction", junction.get("id"))
            repairs.append(Repair(road.sourceline or 0, tag,
                                  f"connecting road of junction {junction.get('id')}: marked so"))  # fmt: skip
    return repairs


def _direct_junctions(root: etree._Element) -> list[Repair]:
    repairs = []
    for junction in root.iter("junction"):
        if junction.get("type") == "direct":
            tag = _tag(junction, "id", "type")
            del junction.attrib["type"]
            repairs.append(
                Repair(
                    junction.sourceline or 0,
                    tag,
                    "direct junction read as an ordinary junction of its road-to-road links",
                )
            )
    return repairs


def _number(el: etree._Element, attr: str) -> float:
    try:
        return float(el.get(attr, "nan"))
    except ValueError:
        return float("nan")


def _where(el: etree._Element) -> str:
    road = next(el.iterancestors("road"), None)
    return f"road {road.get('id')} " if road is not None else ""


def _flat_curves(root: etree._Element) -> list[Repair]:
    """Arcs without curvature as lines, spirals without change of curvature as arcs."""
    repairs = []
    for curve in list(root.iter("arc", "spiral")):
        length = _number(curve.getparent(), "length")
        if curve.tag == "arc":
            k = _number(curve, "curvature")
            if not (k == 0.0 or abs(k) * length**2 / 8 < FLAT):  # sagitta of the arc
                continue
            tag, action = _tag(curve, "curvature"), "read as a line"
            curve.tag = "line"
            del curve.attrib["curvature"]
        else:
            k0, k1 = _number(curve, "curvStart"), _number(curve, "curvEnd")
            if not abs(k1 - k0) * length**2 / 24 < FLAT:  # departure from the mean arc
                continue
            tag = _tag(curve, "curvStart", "curvEnd")
            action = f"constant curvature: read as an arc of curvature {(k0 + k1) / 2:.12g}"
            curve.tag = "arc"
            curve.attrib.clear()
            curve.set("curvature", repr((k0 + k1) / 2))
        repairs.append(Repair(curve.sourceline or 0, _where(curve) + tag, action))
    return repairs


def _untyped_signals(root: etree._Element) -> list[Repair]:
    repairs = []
    for signal in list(root.iter("signal")):
        if not (signal.get("type") or "").strip():
            road = next(signal.iterancestors("road"), None)
            where = f"road {road.get('id')} " if road is not None else ""
            repairs.append(
                Repair(
                    signal.sourceline or 0, where + _tag(signal, "id", "type"), "no type: dropped"
                )
            )
            signal.getparent().remove(signal)
    return repairs


def repair_opendrive(source: str | Path, copy: str | Path) -> list[Repair]:
    """Write to ``copy`` the OpenDRIVE file ``source`` with the repairs netconvert needs.

    Returns the repairs in file order (empty: ``copy`` is an unchanged copy). ``source`` is
    only read. HiyariError (one line) when ``source`` is not well-formed XML.
    """
    try:
        tree = etree.parse(str(source), etree.XMLParser(huge_tree=True, remove_blank_text=False))
    except (etree.XMLSyntaxError, OSError) as exc:
        raise HiyariError(f"{source}: not well-formed XML: {exc}") from None
    root = tree.getroot()
    repairs = (
        _unmarked_connecting_roads(root) + _connections(root) + _direct_junctions(root)
        + _flat_curves(root) + _untyped_signals(root)
    )  # fmt: skip
    with atomic_path(copy) as tmp:
        tree.write(str(tmp), xml_declaration=True, encoding="UTF-8")
    return sorted(repairs, key=lambda r: r.line)
