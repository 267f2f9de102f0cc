"""How the roads of an OpenDRIVE file connect (road links and junction connections), and the
shortest way along them between two road points: the road-level routing that OpenSCENARIO
routes (AssignRouteAction, RoutePosition) need.

A route is a list of legs: a road, the direction it is driven in (+1: towards increasing s)
and the s it is entered and left at. Routing is by road lengths over the reference lines
(Dijkstra); lanes are not considered (every connecting road of a junction counts as passable
both ways, as a lane-less router must take them).
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from hiyari.errors import HiyariError


@dataclass(frozen=True)
class Leg:
    """Road ``road`` driven in ``direction`` (+1 / -1 along s) from ``s0`` to ``s1``, m."""

    road: str
    direction: int
    s0: float
    s1: float

    @property
    def length(self) -> float:
        """Metres along the reference line."""
        return abs(self.s1 - self.s0)


@dataclass(frozen=True)
class RoadGraph:
    """Which (road, direction) each (road, direction) leads to: a road driven forward leaves at
    its end into its successor, backward at its start into its predecessor; a junction
    leads into each connecting road its connections name for the incoming road."""

    lengths: dict[str, float]
    exits: dict[tuple[str, int], tuple[tuple[str, int], ...]]

    @staticmethod
    def from_file(path: str | Path) -> RoadGraph:
        """The graph of the OpenDRIVE file ``path`` (HiyariError naming it when unreadable)."""
        try:
            root = etree.parse(str(path)).getroot()
        except (OSError, etree.XMLSyntaxError) as exc:
            raise HiyariError(f"{path}: cannot read the road links: {exc}") from None
        lengths = {r.get("id", ""): float(r.get("length", "0")) for r in root.findall("road")}
        junctions: dict[str, list[tuple[str, str, str]]] = {}
        for j in root.findall("junction"):
            junctions[j.get("id", "")] = [
                (c.get("incomingRoad", ""), c.get("connectingRoad", ""), c.get("contactPoint", ""))
                for c in j.findall("connection")
            ]
        exits: dict[tuple[str, int], list[tuple[str, int]]] = {}
        for r in root.findall("road"):
            rid = r.get("id", "")
            for tag, direction in (("successor", 1), ("predecessor", -1)):
                link = r.find(f"link/{tag}")
                if link is None:
                    continue
                out = exits.setdefault((rid, direction), [])
                kind, other = link.get("elementType", "road"), link.get("elementId", "")
                if kind == "road":
                    out.append((other, 1 if link.get("contactPoint") == "start" else -1))
                elif kind == "junction":
                    for incoming, connecting, contact in junctions.get(other, []):
                        if incoming == rid:
                            out.append((connecting, 1 if contact == "start" else -1))
        return RoadGraph(lengths, {k: tuple(v) for k, v in exits.items()})

    def route(
        self, start: tuple[str, float, int | None], end: tuple[str, float, int | None]
    ) -> list[Leg]:
        """The shortest legs from road point ``start`` to ``end`` (road id, s, direction or
        None for either). HiyariError when no way connects them."""
        (r0, s0, d0), (r1, s1, d1) = start, end
        best: list[Leg] | None = None
        for da in (d0,) if d0 is not None else (1, -1):
            for db in (d1,) if d1 is not None else (1, -1):
                legs = self._route_directed(r0, s0, da, r1, s1, db)
                if legs is not None and (
                    best is None or sum(x.length for x in legs) < sum(x.length for x in best)
                ):
                    best = legs
        if best is None:
            raise HiyariError(f"no road connects road {r0} (s = {s0:g}) to road {r1} (s = {s1:g})")
        return best

    def _route_directed(
        self, r0: str, s0: float, d0: int, r1: str, s1: float, d1: int
    ) -> list[Leg] | None:
        if r0 == r1 and d0 == d1 and (s1 - s0) * d0 >= 0:
            return [Leg(r0, d0, s0, s1)]
        first = self.lengths[r0] - s0 if d0 > 0 else s0
        # Dijkstra over (road, direction) nodes; a node's cost is the distance to its entry
        queue: list[tuple[float, int, tuple[str, int]]] = []
        came: dict[tuple[str, int], tuple[str, int] | None] = {(r0, d0): None}
        cost = {(r0, d0): 0.0}
        tick = 0
        for nxt in self.exits.get((r0, d0), ()):
            if nxt not in cost or first < cost[nxt]:
                cost[nxt], came[nxt] = first, (r0, d0)
                heapq.heappush(queue, (first, tick := tick + 1, nxt))
        done: set[tuple[str, int]] = set()
        while queue:
            c, _, node = heapq.heappop(queue)
            if node in done:
                continue
            done.add(node)
            if node == (r1, d1):
                return self._legs(came, node, s0, s1)
            through = c + self.lengths.get(node[0], 0.0)
            for nxt in self.exits.get(node, ()):
                if nxt not in done and (nxt not in cost or through < cost[nxt]):
                    cost[nxt], came[nxt] = through, node
                    heapq.heappush(queue, (through, tick := tick + 1, nxt))
        return None

    def _legs(self, came: dict, node: tuple[str, int], s0: float, s1: float) -> list[Leg]:
        nodes = [node]
        while came[nodes[-1]] is not None:
            nodes.append(came[nodes[-1]])
        nodes.reverse()
        legs = []
        for k, (road, d) in enumerate(nodes):
            length = self.lengths[road]
            enter = s0 if k == 0 else (0.0 if d > 0 else length)
            leave = s1 if k == len(nodes) - 1 else (length if d > 0 else 0.0)
            legs.append(Leg(road, d, enter, leave))
        return legs
