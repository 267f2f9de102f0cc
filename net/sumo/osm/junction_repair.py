"""Repairs of a converted OSM net where SUMO's junction logic lets vehicles run into each
other or into pedestrians, one warning line per repair.

SUMO keeps two actors apart inside a junction only where its link logic makes their links
foes and their lane centre lines cross. On a city's extract netconvert leaves these places
where that fails:

- *joined junctions whose car links collide*: inside a cluster of OSM nodes that
  netconvert joins into one junction, two car links cross without being foes (links from
  one road never are: a straight on and a left turn from neighbouring lanes swap sides), or
  pass closer than ``CLOSE_PASS`` without crossing (the opposite through lanes of a
  staggered junction squeezed together). Repair: the cluster is converted again unjoined
  (``--junctions.join-exclude``), node by node, where netconvert's shapes keep them apart.
- *crossings along a car's path*: a pedestrian crossing is a foe of the links from and to
  the edges it crosses only; at a tight junction it lies inside the junction and a
  straight-on car beside it runs along it (netconvert's 4 m crossing width). Repair: the
  crossing is narrowed, keeping its outer edge, until a car on every such link passes at
  least ``CLEARANCE`` from it; one that would get narrower than ``MIN_CROSSING_WIDTH`` is
  kept and reported.
- *dead starts*: a vehicle lane that no lane leads into, starting at a junction inside the
  map (a two-way road piece where the road on is one-way), shorter than the longest vehicle:
  a vehicle inserted there stands in the junction behind it, where SUMO does not see it.
  Repair: the lane is closed to vehicles (and the lanes only it leads into, while as short).

- *lanes of zero length*: netconvert cuts a short road piece whose ends are at different
  heights (a tunnel's ramp between two close junctions) down to a lane whose shape points
  coincide; SUMO puts a person on it, or on the walking area before it, at NaN. Repair:
  the lane gets a straight 0.1 m shape (its length in the net) along its edge.

The crossings and dead starts are applied by netconvert to the net itself (``netconvert -s`` with a
connection file and an edge file). What is left is reported as SUMO's limit, one line per
junction: car links that cross without being foes or pass closer than ``CLOSE_PASS``
without crossing (SUMO's in-junction conflicts are crossings of lane centre lines only),
crossings that cannot be narrowed enough.
"""

from __future__ import annotations

import math
import tempfile
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import shapely
from lxml import etree

from hiyari.net.sumo.junction_check import check_junctions, link_paths
from hiyari.sumo_tools import run_sumo_tool

#: Half the width of a car, m (SUMO's passenger car and hiyari's CAR class are 1.8 m wide; the
#: net layer does not import the traffic layer's size table).
CAR_HALF_WIDTH = 0.9
#: Distance kept between a car's path and a narrowed crossing: half a car and 0.1 m, m.
CLEARANCE = CAR_HALF_WIDTH + 0.1
#: A crossing is not narrowed below this width, m (two people side by side).
MIN_CROSSING_WIDTH = 2.0
#: A dead start shorter than this holds no inserted vehicle of the longest type the demand
#: inserts (a 12 m bus, SUMO's and hiyari's), m.
LONGEST_VEHICLE = 12.0
#: Two car links whose paths pass closer than this without crossing let their cars' bodies
#: overlap by 0.3 m side by side, m (opposite left turns at an ordinary crossroads pass 1.6
#: to 1.8 m apart, and SUMO's cars pass there).
CLOSE_PASS = 1.5


@dataclass(frozen=True)
class CarConflict:
    """Two car links of junction ``junction`` (their internal lanes ``a``, ``b``) that SUMO
    does not keep apart: paths that cross without being foes (``distance`` 0) or pass
    ``distance`` m apart without crossing."""

    junction: str
    a: str
    b: str
    distance: float

    def describe(self) -> str:
        """``a / b cross`` or ``a / b 0.45 m apart``."""
        how = "cross" if self.distance == 0 else f"{self.distance:.2f} m apart"
        return f"{self.a} / {self.b} {how}"


@dataclass
class NetRepairs:
    """What ``plan_repairs`` found. ``crossings``: (junction, crossing edge id, crossed
    edges, width, new width) with new width 0 where the crossing cannot be narrowed enough;
    ``closed``: (lane id, length); ``conflicts``: the car conflicts left (SUMO's limit)."""

    crossings: list[tuple[str, str, str, float, float]] = field(default_factory=list)
    closed: list[tuple[str, float]] = field(default_factory=list)
    conflicts: list[CarConflict] = field(default_factory=list)

    @property
    def any(self) -> bool:
        """Whether netconvert has anything to change."""
        return bool(self.closed or any(c[4] for c in self.crossings))

    def messages(self) -> list[str]:
        """One line per repair, then one per junction where SUMO's limit is left."""
        lines = []
        for j, crossing, edges, width, new in self.crossings:
            if new:
                lines.append(f"junction {j}: crossing {crossing} over {edges} narrowed from "
                             f"{width:g} m to {new:.1f} m, clear of the cars beside it that "
                             "SUMO does not make its foes")  # fmt: skip
            else:
                lines.append(f"junction {j}: crossing {crossing} over {edges} lies in the path "
                             "of car links that are not its foes; SUMO's limit: its junction "
                             "logic does not keep them apart")  # fmt: skip
        for lane, length in self.closed:
            lines.append(f"lane {lane}: no lane leads into it and it is {length:.1f} m long: "
                         "closed to vehicles (one inserted there would stand in the junction "
                         "behind it)")  # fmt: skip
        per_junction: dict[str, list[str]] = defaultdict(list)
        for c in self.conflicts:
            per_junction[c.junction].append(c.describe())
        for j, pairs in per_junction.items():
            lines.append(f"junction {j}: car links that SUMO does not keep apart "
                         f"({'; '.join(pairs)}); SUMO's limit: it separates vehicles inside a "
                         "junction only where foe lanes cross")  # fmt: skip
        return lines


def _opens_to_vehicles(lane: etree._Element) -> bool:
    allow = lane.get("allow")
    if allow is not None:
        return bool(set(allow.split()) - {"pedestrian"})
    return lane.get("disallow", "") != "all"


def _opens_to_cars(lane: etree._Element) -> bool:
    allow = lane.get("allow")
    if allow is not None:
        return "passenger" in allow.split()
    return "passenger" not in lane.get("disallow", "").split() and lane.get("disallow") != "all"


def _car_lanes(root: etree._Element) -> set[str]:
    return {ln.get("id") for e in root.iter("edge") if e.get("function") == "internal"
            for ln in e.iter("lane") if _opens_to_cars(ln)}  # fmt: skip


def _foes(j: etree._Element) -> dict[int, str]:
    return {int(r.get("index")): r.get("foes", "")[::-1] for r in j.iter("request")}


def car_conflicts(root: etree._Element) -> list[CarConflict]:
    """Car links of one junction that cross without being foes, or pass closer than
    CLOSE_PASS without crossing (neither from nor into one lane)."""
    paths, targets, sources = link_paths(root)
    car = _car_lanes(root)
    out = [CarConflict(j, a, b, 0.0) for j, a, b in check_junctions(root).unregulated
           if a in car and b in car]  # fmt: skip
    for j in root.iter("junction"):
        if j.get("type") in ("internal", "dead_end"):
            continue
        links = [ln for ln in (j.get("intLanes") or "").split() if ln in paths and ln in car]
        for k, la in enumerate(links):
            for lb in links[k + 1 :]:
                if targets.get(la) == targets.get(lb) or sources.get(la) == sources.get(lb):
                    continue
                pa, pb = paths[la], paths[lb]
                d = pa.distance(pb)
                if d < CLOSE_PASS and not pa.intersects(pb):
                    out.append(CarConflict(j.get("id"), la, lb, round(d, 2)))
    return out


def clusters_to_unjoin(net: str | Path) -> dict[str, list[str]]:
    """Joined junctions (of several OSM nodes) with car conflicts: junction id -> its OSM
    node ids (netconvert's ``origId``)."""
    root = etree.parse(str(net), etree.XMLParser(huge_tree=True)).getroot()
    bad = {c.junction for c in car_conflicts(root)}
    out = {}
    for j in root.iter("junction"):
        orig = j.find("param[@key='origId']")
        nodes = orig.get("value").split() if orig is not None else []
        if j.get("id") in bad and len(nodes) > 1:
            out[j.get("id")] = nodes
    return out


def _narrowed(
    centre: shapely.LineString, width: float, junction_xy: tuple[float, float], near: list
) -> float:
    """The widest crossing width (0.1 m steps, down to MIN_CROSSING_WIDTH) whose strip, from
    the crossing's outer edge inwards, keeps every path of ``near`` CLEARANCE away; 0 when
    there is none."""
    sides = [centre.offset_curve(s * width / 2) for s in (1.0, -1.0)]
    outer_side = max((1.0, -1.0), key=lambda s: sides[0 if s > 0 else 1].distance(
        shapely.Point(junction_xy)))  # fmt: skip
    w = round(width - 0.1, 1)
    while w >= MIN_CROSSING_WIDTH - 1e-9:
        strip_centre = centre.offset_curve(outer_side * (width - w) / 2)
        strip = strip_centre.buffer(w / 2, cap_style="flat")
        if all(strip.distance(p) >= CLEARANCE for p in near):
            return w
        w = round(w - 0.1, 1)
    return 0.0


def crossings_along_cars(root: etree._Element) -> list[tuple[str, str, str, float, float]]:
    """Crossings a car link that is not their foe passes within half a car's width of:
    (junction, crossing edge id, crossed edges, width, the width that clears them or 0)."""
    paths, _, _ = link_paths(root)
    car = _car_lanes(root)
    crossing = {}
    for e in root.iter("edge"):
        if e.get("function") == "crossing":
            ln = e.find("lane")
            pts = [tuple(map(float, p.split(",")[:2])) for p in ln.get("shape").split()]
            crossing[ln.get("id")] = (e.get("id"), e.get("crossingEdges"),
                                      shapely.LineString(pts), float(ln.get("width", 4.0)))  # fmt: skip
    out = []
    for j in root.iter("junction"):
        links = (j.get("intLanes") or "").split()
        foes = _foes(j)
        for a, la in enumerate(links):
            if la not in crossing or a not in foes:
                continue
            cid, edges, centre, width = crossing[la]
            strip = centre.buffer(width / 2, cap_style="flat")
            near = [paths[lb] for b, lb in enumerate(links)
                    if lb in paths and lb in car and foes[a][b:b + 1] != "1"
                    and strip.distance(paths[lb]) < CAR_HALF_WIDTH]  # fmt: skip
            if near:
                xy = (float(j.get("x")), float(j.get("y")))
                out.append((j.get("id"), cid, edges, width, _narrowed(centre, width, xy, near)))
    return out


def _dead_starts(root: etree._Element) -> list[tuple[str, float]]:
    """Vehicle lanes no open lane leads into, from a junction that is no dead end, shorter
    than LONGEST_VEHICLE; then the lanes only those lead into, while as short."""
    kind = {j.get("id"): j.get("type") for j in root.iter("junction")}
    lanes = {}
    for e in root.iter("edge"):
        if not e.get("function"):
            for ln in e.iter("lane"):
                if _opens_to_vehicles(ln):
                    lanes[ln.get("id")] = (e.get("from"), float(ln.get("length")))
    into: dict[str, set[str]] = defaultdict(set)
    for c in root.iter("connection"):
        if not c.get("from").startswith(":"):
            into[f"{c.get('to')}_{c.get('toLane')}"].add(f"{c.get('from')}_{c.get('fromLane')}")
    closed: dict[str, float] = {}
    changed = True
    while changed:
        changed = False
        for lane, (start, length) in lanes.items():
            if lane in closed or kind.get(start) == "dead_end" or length >= LONGEST_VEHICLE:
                continue
            if not {s for s in into.get(lane, ()) if s in lanes and s not in closed}:
                closed[lane] = length
                changed = True
    return sorted(closed.items())


def _apply(net: Path, repairs: NetRepairs, out: Path, what: str) -> None:
    """Write to ``out`` the net ``net`` with the crossings and lanes of ``repairs``."""
    con = etree.Element("connections")
    for j, _, edges, _, new in repairs.crossings:
        if new:
            etree.SubElement(con, "crossing", node=j, edges=edges, width=f"{new:.1f}")
    edg = etree.Element("edges")
    by_edge: dict[str, list[str]] = defaultdict(list)
    for lane, _ in repairs.closed:
        edge, index = lane.rsplit("_", 1)
        by_edge[edge].append(index)
    for edge, indices in by_edge.items():
        el = etree.SubElement(edg, "edge", id=edge)
        for index in indices:
            etree.SubElement(el, "lane", index=index, disallow="all")
    with tempfile.TemporaryDirectory(prefix="hiyari-net-") as tmp:
        con_file, edg_file = Path(tmp) / "repairs.con.xml", Path(tmp) / "repairs.edg.xml"
        etree.ElementTree(con).write(str(con_file))
        etree.ElementTree(edg).write(str(edg_file))
        run_sumo_tool("netconvert", ["-s", str(net), "--connection-files", str(con_file),
                                     "--edge-files", str(edg_file), "-o", str(out)], what)  # fmt: skip


#: A lane whose shape is shorter than this in plan view has collapsed to a point, m.
_COLLAPSED = 0.05


def _unit(a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float]:
    d = math.dist(a, b)
    return ((b[0] - a[0]) / d, (b[1] - a[1]) / d) if d > 0 else (1.0, 0.0)


def straighten_collapsed(root: etree._Element) -> list[str]:
    """Give every lane whose shape collapsed to a point a straight 0.1 m shape centred on
    it, along its edge (from-junction to to-junction; an internal lane along its junction's
    incoming lane); return the lane ids."""
    xy = {j.get("id"): (float(j.get("x")), float(j.get("y"))) for j in root.iter("junction")}
    shapes = {ln.get("id"): ln.get("shape") for ln in root.iter("lane")}
    into = {c.get("via"): f"{c.get('from')}_{c.get('fromLane')}" for c in root.iter("connection")
            if c.get("via")}  # fmt: skip
    fixed = []
    for e in root.iter("edge"):
        for ln in e.iter("lane"):
            pts = [tuple(map(float, p.split(","))) for p in ln.get("shape").split()]
            run = sum(math.dist(a[:2], b[:2]) for a, b in zip(pts, pts[1:], strict=False))
            if run >= _COLLAPSED:
                continue
            if e.get("function") == "internal" and into.get(ln.get("id")) in shapes:
                before = [tuple(map(float, p.split(",")[:2]))
                          for p in shapes[into[ln.get("id")]].split()]  # fmt: skip
                ux, uy = _unit(before[-2], before[-1])
            else:
                ux, uy = _unit(xy.get(e.get("from"), (0, 0)), xy.get(e.get("to"), (1, 0)))
            x, y, *z = pts[0]
            ends = [(x - 0.05 * ux, y - 0.05 * uy), (x + 0.05 * ux, y + 0.05 * uy)]
            ln.set("shape", " ".join(",".join(f"{v:.2f}" for v in (*p, *z)) for p in ends))
            fixed.append(ln.get("id"))
    return fixed


def repair_net(net: Path, what: str, warn: Callable[[str], None]) -> None:
    """Narrow the crossings, close the dead starts and straighten the collapsed lanes of the
    net ``net`` in place (one ``warn`` line per repair), then report the car conflicts
    left; ``what`` names the user's input in an error."""
    root = etree.parse(str(net), etree.XMLParser(huge_tree=True)).getroot()
    repairs = NetRepairs(crossings=crossings_along_cars(root), closed=_dead_starts(root))
    if repairs.any:
        fixed = net.with_name("repaired." + net.name)
        _apply(net, repairs, fixed, what)
        fixed.replace(net)
        root = etree.parse(str(net), etree.XMLParser(huge_tree=True)).getroot()
    collapsed = straighten_collapsed(root)
    if collapsed:
        etree.ElementTree(root).write(str(net), xml_declaration=True, encoding="UTF-8")
    repairs.conflicts = car_conflicts(root)
    for line in repairs.messages():
        warn(line)
    for lane in collapsed:
        warn(f"lane {lane}: netconvert cut it to a point (a short piece between junctions at "
             "different heights): given a straight 0.1 m shape along its edge (SUMO puts a "
             "person on a lane of zero length at no position)")  # fmt: skip
