"""The road / lane / s frame of a SUMO net that has no OpenDRIVE source (the generated preset
roads), so that the scenario engine runs on it exactly as on an imported map.

Every normal SUMO edge becomes one road with the edge's id. Its reference line is the centre
line of the edge's lane 0 (the rightmost), one straight geometry per polyline segment, and a
constant lane offset puts lane 0's centre at t = 0; the lanes are right lanes in OpenDRIVE
convention, SUMO lane index i of an n-lane edge being lane id -(n - i) with SUMO's width.
So a position ``d`` metres left of lane 0's centre is t = d, and lane k's centre is at the
sum of the widths between (on SUMO's straight, parallel lanes exactly where SUMO has it).
One lane section per road; an edge's successors are its outgoing edges, the one closest to
straight ahead first. Frames: network metres, headings in radians counter-clockwise from +x.
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.errors import HiyariError
from hiyari.net.road.network import RoadNetwork
from hiyari.net.road.opendrive_lanes import (
    Geometry,
    LaneSection,
    LaneSpec,
    OpenDriveMap,
    Poly3,
    Road,
    RoadLanes,
    SumoLane,
)


def sumo_lane_id(edge_lanes: int, index: int) -> int:
    """OpenDRIVE lane id of SUMO lane ``index`` on an edge of ``edge_lanes`` lanes."""
    return -(edge_lanes - index)


def sumo_road_lanes(network: RoadNetwork) -> RoadLanes:
    """The net's edges as OpenDRIVE roads (see the module docstring), linked lane by lane."""
    roads: dict[str, Road] = {}
    links: dict[tuple[str, int, int], SumoLane] = {}
    succ: dict[str, list[str]] = {}
    for edge in network.sumo.getEdges():
        if edge.isSpecial():
            continue
        eid = edge.getID()
        lanes = edge.getLanes()
        n = len(lanes)
        shapes = [np.array([p[:2] for p in ln.getShape()], dtype=float) for ln in lanes]
        roads[eid] = _road(eid, shapes[0], [ln.getWidth() for ln in lanes])
        for ln, pts in zip(lanes, shapes, strict=True):
            links[(eid, sumo_lane_id(n, ln.getIndex()), 0)] = SumoLane.from_shape(
                ln.getID(), eid, ln.getIndex(), pts, ln.getLength()
            )
        out = [e for e in edge.getOutgoing() if not e.isSpecial()]
        succ[eid] = [e.getID() for e in sorted(out, key=lambda e: _turn(shapes[0], e))]
    if not roads:
        raise HiyariError(f"{network.path}: the net has no normal edge")
    return RoadLanes(OpenDriveMap.from_roads(network.path, roads), network.path, (links, succ))


def _road(eid: str, centre0: np.ndarray, widths: list[float]) -> Road:
    """Road ``eid`` along lane 0's centre line ``centre0`` (K, 2) with lane ``widths`` by
    SUMO index."""
    seg = np.diff(centre0, axis=0)
    length = np.linalg.norm(seg, axis=1)
    keep = length > 1e-9
    seg, length, start = seg[keep], length[keep], centre0[:-1][keep]
    if not len(length):
        raise HiyariError(f"edge {eid}: lane 0 has no length")
    s0 = np.concatenate([[0.0], np.cumsum(length)[:-1]])
    geoms = tuple(
        Geometry(float(s), float(p[0]), float(p[1]), math.atan2(d[1], d[0]), float(ln), "line")
        for s, p, d, ln in zip(s0, start, seg, length, strict=True)
    )
    n = len(widths)
    lanes = {
        sumo_lane_id(n, i): LaneSpec(sumo_lane_id(n, i), "driving", (Poly3(0.0, w, 0.0, 0.0, 0.0),))
        for i, w in enumerate(widths)
    }
    lanes[0] = LaneSpec(0, "none", ())
    # lane 0's centre on the reference line: every lane left of it plus half its own width
    offset = sum(widths[1:]) + 0.5 * widths[0]
    total = float(np.sum(length))
    return Road(
        eid,
        total,
        geoms,
        (Poly3(0.0, offset, 0.0, 0.0, 0.0),),
        (LaneSection(0, 0.0, total, lanes),),
        (),
        False,
    )


def _turn(centre0: np.ndarray, edge: object) -> float:
    """Absolute heading change (rad) from the end of ``centre0`` into ``edge``."""
    a = centre0[-1] - centre0[-2]
    shape = np.array([p[:2] for p in edge.getLanes()[0].getShape()], dtype=float)
    b = shape[1] - shape[0]
    return abs(math.remainder(math.atan2(b[1], b[0]) - math.atan2(a[1], a[0]), 2 * math.pi))
