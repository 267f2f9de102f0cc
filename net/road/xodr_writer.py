"""OpenDRIVE 1.6 roads for the JAMA traffic-disturbance catalogue, written with lxml.

Four geometries (JAMA §4.1.1.1): a motorway main line, a merge and a branch (one carriageway,
right-hand traffic, straight along +x from the origin), and a four-leg intersection (one lane
per direction, legs along the axes, junction at the origin).

Motorway lanes: road "main", lane -1 is the leftmost (fast) lane next to the reference line,
lane -n the rightmost. The merge adds lane -(n+1) (the acceleration lane, type "driving") from
s = 0 to ``merge_end`` (where it ends); the branch opens lane -(n+1) (the deceleration / exit
lane) at ``branch_start`` and keeps it to the road's end. Lanes start and end at full width
(no taper): netconvert splits a tapering lane section into several edges where the width
crosses its minimum, and the lane sections must map one to one onto SUMO edges.

Intersection: legs "west", "south", "east", "north" start at ``approach`` m from the centre
and run outward (s = 0 at the junction); lane 1 drives toward the junction, lane -1 away.
Connecting roads "<from>-<to>" (straight lines and quarter arcs) join every inbound lane to
the other three legs' outbound lanes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError

GEOMETRIES = ("main", "merge", "branch", "intersection")
#: Road id of the motorway carriageway.
MAIN_ROAD = "main"
#: Intersection legs with their outward headings, rad.
LEGS = {"west": math.pi, "south": -math.pi / 2, "east": 0.0, "north": math.pi / 2}


@dataclass(frozen=True)
class CatalogueRoad:
    """One generated road. Lengths m. ``lanes``: through lanes per direction (motorway 2 or 3;
    the intersection has one per direction)."""

    geometry: str = "main"
    lanes: int = 2
    lane_width: float = 3.5
    length: float = 1500.0
    merge_end: float = 700.0  # acceleration lane at full width until here
    branch_start: float = 700.0  # exit lane from here to the end
    approach: float = 12.0  # intersection: junction half size
    leg_length: float = 300.0
    speed_limit: float = 36.11  # m/s on motorway lanes (130 km/h, the ego's design speed)
    town_speed_limit: float = 16.67  # m/s at the intersection (60 km/h)

    def validate(self) -> None:
        """HiyariError for an unknown geometry or impossible sizes."""
        if self.geometry not in GEOMETRIES:
            raise HiyariError(f"road geometry {self.geometry!r}: one of {', '.join(GEOMETRIES)}")
        if not 1 <= self.lanes <= 6:
            raise HiyariError(f"road: lanes per direction must be 1..6, got {self.lanes}")
        if not 2.5 <= self.lane_width <= 5.0:
            raise HiyariError(f"road: lane width must be 2.5..5 m, got {self.lane_width}")
        ends = (self.merge_end, self.branch_start)
        if self.geometry in ("merge", "branch") and not 0 < min(ends) <= max(ends) < self.length:
            raise HiyariError(
                f"road: merge/branch stations must lie inside the {self.length} m road"
            )
        if self.geometry == "intersection" and self.approach <= self.lane_width:
            raise HiyariError("road: intersection approach must exceed the lane width")

    @property
    def extra_lane(self) -> int | None:
        """OpenDRIVE id of the merge / exit lane (None on a main line or intersection)."""
        return -(self.lanes + 1) if self.geometry in ("merge", "branch") else None


def _root(name: str) -> etree._Element:
    root = etree.Element("OpenDRIVE")
    etree.SubElement(
        root, "header", revMajor="1", revMinor="6", name=name, vendor="hiyari", version="1"
    )
    return root


def _road(root: etree._Element, rid: str, length: float, junction: str = "-1") -> etree._Element:
    return etree.SubElement(
        root, "road", id=rid, name=rid, length=repr(length), junction=junction, rule="RHT"
    )


def _geometry(plan: etree._Element, x: float, y: float, hdg: float, length: float,
              curvature: float = 0.0) -> None:  # fmt: skip
    g = etree.SubElement(
        plan, "geometry", s="0", x=repr(x), y=repr(y), hdg=repr(hdg), length=repr(length)
    )
    if curvature == 0.0:
        etree.SubElement(g, "line")
    else:
        etree.SubElement(g, "arc", curvature=repr(curvature))


def _lane(parent: etree._Element, lid: int, width: tuple[float, float, float, float],
          links: tuple[int | None, int | None] = (None, None),
          speed: float = 0.0) -> None:  # fmt: skip
    lane = etree.SubElement(parent, "lane", id=str(lid), type="driving", level="false")
    link = etree.SubElement(lane, "link")
    for tag, other in zip(("predecessor", "successor"), links, strict=True):
        if other is not None:
            etree.SubElement(link, tag, id=str(other))
    a, b, c, d = width
    etree.SubElement(lane, "width", sOffset="0", a=repr(a), b=repr(b), c=repr(c), d=repr(d))
    etree.SubElement(lane, "roadMark", sOffset="0", type="solid" if lid in (-1, 1) else "broken",
                     color="standard", width="0.15")  # fmt: skip
    if speed > 0:
        etree.SubElement(lane, "speed", sOffset="0", max=repr(speed), unit="m/s")


def _section(lanes_el: etree._Element, s: float, right: list[tuple], speed: float) -> None:
    """A lane section from ``s`` with right lanes ``(id, width poly, links)``."""
    sec = etree.SubElement(lanes_el, "laneSection", s=repr(s))
    centre = etree.SubElement(sec, "center")
    etree.SubElement(etree.SubElement(centre, "lane", id="0", type="none", level="false"), "link")
    side = etree.SubElement(sec, "right")
    for lid, width, links in right:
        _lane(side, lid, width, links, speed)


def _motorway(p: CatalogueRoad) -> etree._Element:
    root = _root(f"hiyari JAMA {p.geometry} {p.lanes} lanes")
    road = _road(root, MAIN_ROAD, p.length)
    etree.SubElement(road, "link")
    etree.SubElement(road, "type", s="0", type="motorway")
    _geometry(etree.SubElement(road, "planView"), 0.0, 0.0, 0.0, p.length)
    lanes_el = etree.SubElement(road, "lanes")
    full = (p.lane_width, 0.0, 0.0, 0.0)
    through = [(-i, full) for i in range(1, p.lanes + 1)]
    x = p.extra_lane
    if x is None:
        sections = [(0.0, [], None)]
    elif p.geometry == "merge":
        sections = [(0.0, [(x, full)], None), (p.merge_end, [], None)]
    else:
        sections = [(0.0, [], None), (p.branch_start, [(x, full)], None)]
    for k, (s, extra, _) in enumerate(sections):
        ids_prev = _ids(sections, k - 1, p) if k > 0 else set()
        ids_next = _ids(sections, k + 1, p) if k + 1 < len(sections) else set()
        right = [
            (lid, w, (lid if lid in ids_prev else None, lid if lid in ids_next else None))
            for lid, w in [*through, *extra]
        ]
        _section(lanes_el, s, right, p.speed_limit)
    return root


def _ids(sections: list, k: int, p: CatalogueRoad) -> set[int]:
    return {-i for i in range(1, p.lanes + 1)} | {lid for lid, _ in sections[k][1]}


def _intersection(p: CatalogueRoad) -> etree._Element:
    root = _root("hiyari JAMA intersection")
    w, r0 = p.lane_width, p.approach
    for name, hdg in LEGS.items():
        road = _road(root, name, p.leg_length)
        etree.SubElement(
            etree.SubElement(road, "link"), "predecessor", elementType="junction", elementId="1"
        )
        etree.SubElement(road, "type", s="0", type="town")
        _geometry(etree.SubElement(road, "planView"), r0 * math.cos(hdg), r0 * math.sin(hdg),
                  hdg, p.leg_length)  # fmt: skip
        sec = etree.SubElement(etree.SubElement(road, "lanes"), "laneSection", s="0")
        left = etree.SubElement(sec, "left")
        _lane(left, 1, (w, 0.0, 0.0, 0.0), speed=p.town_speed_limit)
        centre = etree.SubElement(sec, "center")
        etree.SubElement(
            etree.SubElement(centre, "lane", id="0", type="none", level="false"), "link"
        )
        _lane(etree.SubElement(sec, "right"), -1, (w, 0.0, 0.0, 0.0), speed=p.town_speed_limit)
    junction = etree.Element("junction", id="1", name="centre")
    for a, ha in LEGS.items():
        for b, hb in LEGS.items():
            if a == b:
                continue
            cid = f"{a}-{b}"
            h0 = ha + math.pi  # inbound heading
            x0 = r0 * math.cos(ha) - 0.5 * w * math.sin(ha)  # t = +w/2 on leg a
            y0 = r0 * math.sin(ha) + 0.5 * w * math.cos(ha)
            turn = math.remainder(hb - h0, 2 * math.pi)
            if abs(turn) < 1e-9:
                length, k = 2 * r0, 0.0
            else:
                radius = r0 + 0.5 * w if turn > 0 else r0 - 0.5 * w
                length, k = radius * abs(turn), math.copysign(1.0 / radius, turn)
            road = _road(root, cid, length, junction="1")
            link = etree.SubElement(road, "link")
            etree.SubElement(link, "predecessor", elementType="road", elementId=a,
                             contactPoint="start")  # fmt: skip
            etree.SubElement(link, "successor", elementType="road", elementId=b,
                             contactPoint="start")  # fmt: skip
            _geometry(etree.SubElement(road, "planView"), x0, y0, h0, length, k)
            _section(etree.SubElement(road, "lanes"), 0.0, [(-1, (w, 0.0, 0.0, 0.0), (1, -1))],
                     p.town_speed_limit)  # fmt: skip
            con = etree.SubElement(junction, "connection", id=str(len(junction)),
                                   incomingRoad=a, connectingRoad=cid, contactPoint="start")  # fmt: skip
            etree.SubElement(con, "laneLink", attrib={"from": "1", "to": "-1"})
    root.append(junction)
    return root


def write_catalogue_road(out: str | Path, road: CatalogueRoad) -> Path:
    """Write ``road`` as OpenDRIVE 1.6 to ``out`` (atomically) and return the path."""
    road.validate()
    root = _intersection(road) if road.geometry == "intersection" else _motorway(road)
    data = etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)
    with atomic_path(out) as target:
        Path(target).write_bytes(data)
    return Path(out)
