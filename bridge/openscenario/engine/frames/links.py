"""Distances along the road network between points on different roads: how far a point on one
road is ahead of (or behind) a point on another when the roads are linked (successor /
predecessor links, junction connecting roads), and where a point lies some metres along the
network from another. Measured along the roads' reference lines (s), the road frame's
distance; ``frames.lane`` uses it for the stretch off the measuring entity's road.
"""

from __future__ import annotations

import math

from hiyari.errors import HiyariError
from hiyari.net.road.topology import RoadGraph


def road_ahead(
    graph: RoadGraph, road_a: str, s_a: float, direction: float, road_b: str, s_b: float
) -> float:
    """Metres (along the reference lines) that road point (``road_b``, ``s_b``) is ahead of
    (``road_a``, ``s_a``) for travel in ``direction`` (+1 / -1 along road a's s); negative
    when behind; the shorter way when both are possible; NaN when no road links them."""
    if road_a == road_b:
        return (s_b - s_a) * direction
    d = 1 if direction >= 0 else -1
    best = math.nan
    for sign in (1, -1):
        try:
            legs = graph.route((road_a, s_a, sign * d), (road_b, s_b, None))
        except (HiyariError, KeyError):
            continue
        length = sum(leg.length for leg in legs)
        if math.isnan(best) or length < abs(best):
            best = sign * length
    return best


def walk(
    graph: RoadGraph, road: str, s: float, direction: int, distance: float, prefer: str = ""
) -> tuple[str, float, int]:
    """The road point ``distance`` m (negative: backwards) from (``road``, ``s``) travelling in
    ``direction`` (+1 / -1 along s), continued over the road links past a road's end (into
    ``prefer`` where it is one of the ways on, else the first link): its road, s and the
    travel direction there (-1 where the road is entered at its end). At a road end with no
    link it stays on the end."""
    move = direction if distance >= 0 else -direction
    left = abs(distance)
    for _ in range(64):  # a few links at most; bounded against cyclic nets of tiny roads
        length = graph.lengths[road]
        room = length - s if move > 0 else s
        if left <= room:
            s = s + move * left
            break
        nxt = graph.exits.get((road, move), ())
        if not nxt:
            s = length if move > 0 else 0.0
            break
        left -= room
        new_road, new_move = next((x for x in nxt if x[0] == prefer), nxt[0])
        direction = direction * move * new_move  # the travel direction turns with the road's
        road, move = new_road, new_move
        s = 0.0 if move > 0 else graph.lengths[road]
    return road, s, direction
