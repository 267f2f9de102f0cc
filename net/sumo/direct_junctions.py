"""The lane links of OpenDRIVE direct junctions, made exact in the SUMO net.

A direct junction (``<junction type="direct">``, OpenDRIVE 1.8) joins an incoming road and a
linked road without connecting roads; each ``<laneLink from to>`` joins a lane of the incoming
road to a lane of the linked road, and traffic flows along it in the lanes' driving direction
(a right-hand road's left lanes run from the linked road into the incoming road). netconvert
reads such a junction, once the repair pre-pass has turned it into an ordinary one, keyed on
the incoming road only: links of a linked road that is also incoming elsewhere are lost, and
edges without a link of their own get netconvert's guessed turns (across the median, into the
other carriageway's exit). The import therefore compares the net's links at each direct
junction with the file's and hands netconvert the difference as a connection file
(``--connection-files``: ``<delete>`` for the extra links and ``<connection>`` for every link
of the file: netconvert builds only the listed links of an edge the file names, so links it
had guessed right would otherwise be lost).

Lanes are matched by the OpenDRIVE identity netconvert keeps (``origId`` "<road>_<lane>") on
the edges at the junction's node (netconvert names the node after the junction id). Only lanes
open to vehicles count: pedestrians go from sidewalk to sidewalk over walking areas whatever
the lane links, and closed lanes carry no traffic.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from hiyari.atomic import atomic_path

#: A SUMO lane-to-lane link: (from lane id, to lane id), e.g. ("-1_0", "-2_0").
Link = tuple[str, str]


@dataclass(frozen=True)
class DirectJunction:
    """One direct junction of the file: its lane links and the road pairs it leaves to
    netconvert (connections without laneLink, whose lanes the file does not name)."""

    id: str
    lane_links: tuple[tuple[str, str, str, str], ...]  # (road, lane, road, lane)
    open_pairs: frozenset[frozenset[str]] = field(default_factory=frozenset)


def direct_junctions(root: etree._Element) -> list[DirectJunction]:
    """The direct junctions of an OpenDRIVE document, in file order."""
    out = []
    for junction in root.iter("junction"):
        if junction.get("type") != "direct":
            continue
        links, open_pairs = [], set()
        for con in junction.findall("connection"):
            incoming = con.get("incomingRoad")
            linked = con.get("linkedRoad") or con.get("connectingRoad")
            if not incoming or not linked:
                continue
            lane_links = con.findall("laneLink")
            if not lane_links:
                open_pairs.add(frozenset((incoming, linked)))
            for ll in lane_links:
                links.append((incoming, ll.get("from", ""), linked, ll.get("to", "")))
        out.append(DirectJunction(junction.get("id", ""), tuple(links), frozenset(open_pairs)))
    return out


@dataclass(frozen=True)
class _NodeLanes:
    """The lanes at one node: by OpenDRIVE identity, whether they enter it, their road."""

    lanes: dict[tuple[str, str], tuple[str, bool]]  # (road, lane) -> (SUMO lane id, enters)
    road: dict[str, str]  # SUMO lane id -> OpenDRIVE road id


def _node_lanes(net: etree._Element, node: str) -> _NodeLanes:
    lanes: dict[tuple[str, str], tuple[str, bool]] = {}
    road: dict[str, str] = {}
    for edge in net.iterfind("edge"):
        if edge.get("function") == "internal" or node not in (edge.get("from"), edge.get("to")):
            continue
        enters = edge.get("to") == node
        for lane in edge.iterfind("lane"):
            if lane.get("allow") == "pedestrian" or lane.get("disallow") == "all":
                continue  # sidewalks (pedestrians cross by walking areas) and closed lanes
            for param in lane.iterfind("param[@key='origId']"):
                rid, _, lid = param.get("value", "").rpartition("_")
                lanes[(rid, lid)] = (lane.get("id", ""), enters)
                road[lane.get("id", "")] = rid
    return _NodeLanes(lanes, road)


def _net_links(net: etree._Element, node: str) -> set[Link]:
    entering = {
        e.get("id") for e in net.iterfind("edge") if e.get("to") == node and not e.get("function")
    }
    return {
        (f"{c.get('from')}_{c.get('fromLane')}", f"{c.get('to')}_{c.get('toLane')}")
        for c in net.iterfind("connection")
        if c.get("from") in entering and not c.get("to", "").startswith(":")  # walking areas
    }


@dataclass(frozen=True)
class Patch:
    """What the net lacks and has too many at the direct junctions, and file links whose two
    lanes both enter or both leave the junction (no way to drive them)."""

    missing: tuple[Link, ...]
    extra: tuple[Link, ...]
    unusable: tuple[str, ...]
    wanted: tuple[Link, ...] = ()  # every link of the file at the direct junctions

    def __bool__(self) -> bool:
        return bool(self.missing or self.extra)


def compare_links(net_path: str | Path, junctions: list[DirectJunction]) -> Patch:
    """The difference between the SUMO net's links at the direct junctions and the file's."""
    net = etree.parse(str(net_path)).getroot()
    missing: set[Link] = set()
    extra: set[Link] = set()
    every: set[Link] = set()
    unusable: list[str] = []
    for j in junctions:
        at = _node_lanes(net, j.id)
        wanted: set[Link] = set()
        for road_a, lane_a, road_b, lane_b in j.lane_links:
            a, b = at.lanes.get((road_a, lane_a)), at.lanes.get((road_b, lane_b))
            if a is None or b is None:  # a lane type the import leaves out
                continue
            if a[1] == b[1]:
                unusable.append(f"junction {j.id} laneLink road {road_a} lane {lane_a} -> "
                                f"road {road_b} lane {lane_b}")  # fmt: skip
                continue
            wanted.add((a[0], b[0]) if a[1] else (b[0], a[0]))
        have = {link for link in _net_links(net, j.id) if link[0] in at.road}
        every |= wanted
        missing |= wanted - have
        extra |= {
            link
            for link in have - wanted
            if frozenset(at.road.get(lane, "") for lane in link) not in j.open_pairs
        }
    return Patch(
        tuple(sorted(missing)), tuple(sorted(extra)), tuple(unusable), tuple(sorted(every))
    )


def _split(lane: str) -> tuple[str, str]:
    edge, _, index = lane.rpartition("_")
    return edge, index


def write_connections(patch: Patch, path: str | Path) -> Path:
    """The patch as a netconvert connection file at ``path``."""
    root = etree.Element("connections")
    for tag, links in (("delete", patch.extra), ("connection", patch.wanted)):
        for a, b in links:
            (fe, fl), (te, tl) = _split(a), _split(b)
            etree.SubElement(root, tag, attrib={"from": fe, "to": te, "fromLane": fl,
                                                "toLane": tl})  # fmt: skip
    with atomic_path(path) as tmp:
        etree.ElementTree(root).write(str(tmp), xml_declaration=True, encoding="UTF-8")
    return Path(path)
