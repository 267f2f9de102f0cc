"""Heights of an OpenStreetMap extract's bridges and tunnels, for netconvert.

OSM maps no road heights, only the vertical order of ways that cross: ``layer=*`` (an
integer, 0 on the ground), implied by ``bridge=*`` (1) and ``tunnel=*`` (-1) where no layer
is given (``tunnel=building_passage``, a passage through a building, is on the ground). A
road of level L is put ``L * LEVEL_HEIGHT`` metres above the ground, so a car on a bridge
passes over the street below it, in the simulation (SUMO's 3-D positions), in the contact
check and in the 3D scene.

The heights are node heights, written into the repaired copy as ``ele`` tags that netconvert
reads with ``--osm.elevation`` (the extract's own ``ele`` values, altitudes above sea level,
are dropped: every other road stays at 0 m). A node takes the level of the road ways through
it; where levels meet:

- a node inside a ground-level way (a footway tunnel mapped onto the street above) stays on
  the ground;
- otherwise (a bridge's or tunnel's end, where its approach road ends) it takes the level
  farthest from the ground, so the approach road carries the ramp, not the bridge.

The ramp is a straight slope along the approach road's first edge; the ways between two
structures of different levels (layer -3 to -4) slope the same way. No slope is steeper
than ``MAX_GRADE``: a node closer to the ground along the roads than its height allows is
lowered towards the ground (netconvert cuts a short steep piece at its junctions down to a
lane of zero length, where SUMO puts a walking person at no position at all).
"""

from __future__ import annotations

import heapq
import math
from collections import defaultdict

from lxml import etree

#: Height of one OSM layer, m: 4.5 m clearance under a bridge plus its deck, rounded up; it
#: also keeps a 4 m truck on the lower level clear of a car on the upper one.
LEVEL_HEIGHT = 6.0
#: The steepest slope between two nodes of a road, rise over run (1:4; ramps are built
#: at 1:8 to 1:20, stairs at 1:2).
MAX_GRADE = 0.25
#: Metres per degree of latitude on SUMO's projection sphere (node distances for the slopes).
M_PER_DEG = 6378137.0 * math.pi / 180.0


def way_level(tags: dict[str, str]) -> int:
    """The OSM level of a way with ``tags``: its ``layer`` (the first integer of a ``;``
    list), else 1 on a bridge, -1 in a tunnel (not a building passage), else 0."""
    layer = (tags.get("layer") or "").split(";")[0].strip()
    if layer.lstrip("+-").isdigit():
        return int(layer)
    if tags.get("bridge", "no") != "no":
        return 1
    if tags.get("tunnel", "no") not in ("no", "building_passage"):
        return -1
    return 0


def node_levels(root: etree._Element) -> dict[str, int]:
    """OSM level per node id of the ``highway=*`` ways, for the nodes not on the ground
    (see the module docstring for where levels meet)."""
    levels: dict[str, set[int]] = defaultdict(set)
    inside_ground: set[str] = set()
    for way in root.iterchildren("way"):
        tags = {t.get("k"): t.get("v") for t in way.iterchildren("tag")}
        if "highway" not in tags:
            continue
        level = way_level(tags)
        refs = [nd.get("ref") for nd in way.iterchildren("nd")]
        for k, ref in enumerate(refs):
            levels[ref].add(level)
            if level == 0 and 0 < k < len(refs) - 1:
                inside_ground.add(ref)
    out = {}
    for ref, found in levels.items():
        if ref in inside_ground:
            continue
        level = max(found, key=lambda v: (abs(v), v))
        if level:
            out[ref] = level
    return out


def node_heights(root: etree._Element) -> dict[str, float]:
    """Height per node id off the ground, m: its level's, lowered where a slope along the
    roads to a node nearer the ground would exceed MAX_GRADE (see the module docstring)."""
    levels = node_levels(root)
    if not levels:
        return {}
    xy = {}
    for node in root.iterchildren("node"):
        lat, lon = float(node.get("lat")), float(node.get("lon"))
        xy[node.get("id")] = (lon * M_PER_DEG * math.cos(math.radians(lat)), lat * M_PER_DEG)
    near: dict[str, list[tuple[str, float]]] = defaultdict(list)
    for way in root.iterchildren("way"):
        if way.find("tag[@k='highway']") is None:
            continue
        refs = [nd.get("ref") for nd in way.iterchildren("nd") if nd.get("ref") in xy]
        for a, b in zip(refs, refs[1:], strict=False):
            d = math.dist(xy[a], xy[b])
            near[a].append((b, d))
            near[b].append((a, d))
    # Dijkstra on the height above or below the ground: a node is at most MAX_GRADE times
    # its distance from any lower node higher than that node
    rise = {n: abs(level) * LEVEL_HEIGHT for n, level in levels.items()}
    queue = [(0.0, n) for n in near if n not in rise] + [(h, n) for n, h in rise.items()]
    heapq.heapify(queue)
    done: set[str] = set()
    while queue:
        h, n = heapq.heappop(queue)
        if n in done:
            continue
        done.add(n)
        for m, d in near[n]:
            if m in rise and m not in done and h + MAX_GRADE * d < rise[m]:
                rise[m] = h + MAX_GRADE * d
                heapq.heappush(queue, (rise[m], m))
    return {n: math.copysign(round(h, 2), levels[n]) for n, h in rise.items() if round(h, 2)}


def write_levels(root: etree._Element) -> int:
    """Replace every node's ``ele`` tag by its height off the ground (none on the ground);
    return how many nodes are off the ground."""
    heights = node_heights(root)
    for node in root.iterchildren("node"):
        for tag in node.findall("tag[@k='ele']"):
            node.remove(tag)
        z = heights.get(node.get("id"))
        if z:
            etree.SubElement(node, "tag", k="ele", v=f"{z:g}")
    return len(heights)
