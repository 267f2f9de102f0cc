"""Check a SUMO net's junctions: do the links SUMO lets pass unhindered stay apart?

SUMO decides who yields at a junction from its link logic (``<request foes=...>``), not from
the internal lane shapes vehicles then follow. When the two disagree the simulation is wrong
in one of two ways:
- *unregulated crossings*: two links that SUMO does not treat as foes but whose paths cross
  (vehicles drive into each other: collisions that the map does not have);
- *phantom conflicts*: two links that SUMO treats as foes although their paths neither cross
  nor merge into one lane (vehicles wait for nothing).

Paths are the internal lane chains of each link (``via`` lanes, split at internal junctions),
as plan-view polylines in network metres.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import shapely
import shapely.ops
from lxml import etree

#: Paths are shortened by this much at both ends before testing them: links that leave the
#: same lane or enter neighbouring lanes touch there without crossing, m.
END_TRIM = 0.5


@dataclass(frozen=True)
class JunctionReport:
    """Link pairs per problem: (junction id, internal lane a, internal lane b)."""

    unregulated: list[tuple[str, str, str]] = field(default_factory=list)
    phantom: list[tuple[str, str, str]] = field(default_factory=list)

    @property
    def clean(self) -> bool:
        """No unregulated crossing and no phantom conflict."""
        return not self.unregulated and not self.phantom

    def summary(self) -> str:
        """One phrase: counts and the first junction of each kind."""
        parts = []
        for name, items in (("unregulated crossings", self.unregulated),
                            ("phantom conflicts", self.phantom)):  # fmt: skip
            if items:
                parts.append(f"{len(items)} {name} (first at junction {items[0][0]})")
        return ", ".join(parts) or "clean"


def link_paths(
    root: etree._Element,
) -> tuple[dict[str, shapely.LineString], dict[str, str], dict[str, str]]:
    """Per internal lane that starts a link, or is listed for it after an internal junction:
    the link's whole internal path, its target and source lane."""
    shapes = {
        ln.get("id"): [tuple(map(float, p.split(",")[:2])) for p in ln.get("shape", "").split()]
        for e in root.iter("edge")
        if e.get("function") == "internal"
        for ln in e.iter("lane")
    }
    nxt: dict[str, str] = {}
    target: dict[str, str] = {}
    source: dict[str, str] = {}
    for c in root.iter("connection"):
        via = c.get("via")
        src = f"{c.get('from')}_{c.get('fromLane')}"
        if via and src not in shapes:
            source[via] = src
        if src in shapes:  # internal -> internal (after an internal junction) or -> outgoing
            if via:
                nxt[src] = via
            else:
                target[src] = f"{c.get('to')}_{c.get('toLane')}"
    paths, targets = {}, {}
    for first in shapes:
        chain, lane = [shapes[first]], first
        while lane in nxt and len(chain) < 8:
            lane = nxt[lane]
            chain.append(shapes[lane])
        points = [p for part in chain for p in part]
        if len(points) >= 2:
            line = shapely.LineString(points)
            trimmed = shapely.ops.substring(line, END_TRIM, max(line.length - END_TRIM, END_TRIM))
            paths[first] = trimmed
            targets[first] = target.get(lane, lane)
    # a link that waits at an internal junction is listed in its junction's intLanes by the
    # lane after that internal junction: it stands for the whole path from the first lane
    for first, second in nxt.items():
        if first in source and first in paths:
            paths[second], targets[second] = paths[first], targets[first]
            source[second] = source[first]
    return paths, targets, source


def check_junctions(net: str | Path | etree._Element) -> JunctionReport:
    """Compare every junction's link logic with its link paths (see the module docstring);
    ``net`` is a net file or its parsed root."""
    if isinstance(net, etree._Element):
        root = net
    else:
        root = etree.parse(str(net), etree.XMLParser(huge_tree=True)).getroot()
    paths, targets, sources = link_paths(root)
    report = JunctionReport()
    for j in root.iter("junction"):
        if j.get("type") in ("internal", "dead_end"):
            continue
        links = (j.get("intLanes") or "").split()
        foes = {int(r.get("index")): r.get("foes", "")[::-1] for r in j.iter("request")}
        for a in range(len(links)):
            for b in range(a + 1, len(links)):
                la, lb = links[a], links[b]
                if la not in paths or lb not in paths or a not in foes:
                    continue
                foe = b < len(foes[a]) and foes[a][b] == "1"
                crossing = paths[la].intersects(paths[lb])
                # vehicles of one lane follow each other; into one lane they merge: no crossing
                merging = targets.get(la, la) == targets.get(lb, lb) or sources.get(
                    la, la
                ) == sources.get(lb, lb)
                if crossing and not foe and not merging:
                    report.unregulated.append((j.get("id"), la, lb))
                elif foe and not crossing and not merging:
                    report.phantom.append((j.get("id"), la, lb))
    return report
