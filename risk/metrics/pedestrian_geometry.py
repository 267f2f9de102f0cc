"""Road geometry the SCT metrics need, read once from a SUMO network.

Frames and units: SUMO network coordinates in metres (x east, y north), as in WorldState.
Three things are extracted:

- kerb segments: where a pedestrian standing on the footway could step into the carriageway
  (the carriageway edges of the road arms, and the two ends of every crossing), each with the
  unit normal pointing into the carriageway / along the crossing (the dart-out direction);
- crossings: each crossing as a rectangle with its walking direction (post-encroachment
  time, and where a vehicle must not stop);
- the carriageway: the arms' vehicle lanes, continued straight across the junction, as one
  polygon. Pedestrians outside it (footways, the corners of the junction) are protected: SUMO's
  tight junction corners let turning vehicles sweep over the kerb where pedestrians wait
  (see hiyari.traffic.collision), which is geometry, not contact;
- vehicle paths: the centre-line polyline a vehicle follows along a route (lanes and the
  junction-internal lanes between them), for predicting vehicles along their route.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import shapely
import sumolib
from sumolib.net import Net
from sumolib.net.edge import Edge
from sumolib.net.lane import Lane

from hiyari.errors import HiyariError


@dataclass(frozen=True)
class KerbSegments:
    """K kerb segments (metres): ``a`` -> ``b`` along the kerb, ``inward`` unit normal into the
    carriageway (arm kerbs) or along the crossing (crossing ends); ``crossing`` is the index of
    the crossing for crossing ends, -1 for arm kerbs."""

    a: np.ndarray  # (K, 2)
    b: np.ndarray  # (K, 2)
    inward: np.ndarray  # (K, 2)
    crossing: np.ndarray  # (K,) int

    def __len__(self) -> int:
        return len(self.a)


@dataclass(frozen=True)
class Crossings:
    """C pedestrian crossings as rectangles: centre (C, 2) m, unit direction along the walk
    (C, 2), half length along it and half width across it (C,) m, corners (C, 4, 2)
    counter-clockwise, and the crossing lane ids."""

    centre: np.ndarray
    direction: np.ndarray
    half_length: np.ndarray
    half_width: np.ndarray
    corners: np.ndarray
    lanes: list[str]

    def __len__(self) -> int:
        return len(self.centre)

    def index(self) -> dict[str, int]:
        """Crossing lane id -> row."""
        return {ln: k for k, ln in enumerate(self.lanes)}


@dataclass
class NetGeometry:
    """Kerbs, crossing conflict areas and route paths of one SUMO network."""

    net_file: Path
    crossing_ids: list[str]  # crossing edge ids, e.g. ':C_c0'
    crossing_lanes: frozenset[str]  # their lane ids, e.g. ':C_c0_0'
    footway_lanes: frozenset[str]  # sidewalk and walking-area lane ids
    walkingarea_lanes: frozenset[str]  # walking-area lane ids (junction corners)
    carriageway: object  # shapely geometry: where pedestrians are exposed to vehicles
    kerbs: KerbSegments
    crossings: Crossings
    junction_xy: np.ndarray  # (J, 2) centres of junctions that have crossings, metres
    _net: object = field(repr=False)
    _paths: dict[tuple[str, ...], np.ndarray] = field(default_factory=dict, repr=False)

    @staticmethod
    def from_net(net_file: str | Path, junctions: Collection[str] | None = None) -> NetGeometry:
        """Read ``net_file`` (a SUMO .net.xml with sidewalks and crossings); ``junctions``:
        only the crossings of these junctions (ids) are studied (None: every crossing)."""
        net_file = Path(net_file)
        if not net_file.is_file():
            raise HiyariError(f"{net_file}: network not found")
        try:
            net = sumolib.net.readNet(
                str(net_file), withInternal=True, withPedestrianConnections=True
            )
        except Exception as exc:  # sumolib raises plain SAX / KeyError on broken files
            raise HiyariError(f"{net_file}: not a readable SUMO network ({exc})") from None
        crossings = [
            e
            for e in net.getEdges(withInternal=True)
            if e.getFunction() == "crossing"
            and (junctions is None or e.getFromNode().getID() in junctions)
        ]
        footways = [
            ln.getID()
            for e in net.getEdges(withInternal=True)
            for ln in e.getLanes()
            if e.getFunction() == "walkingarea" or (e.getFunction() == "" and _pedestrian_only(ln))
        ]
        junctions = {c.getFromNode().getID() for c in crossings}
        return NetGeometry(
            net_file=net_file,
            crossing_ids=[c.getID() for c in crossings],
            crossing_lanes=frozenset(c.getLanes()[0].getID() for c in crossings),
            footway_lanes=frozenset(footways),
            walkingarea_lanes=frozenset(
                ln.getID()
                for e in net.getEdges(withInternal=True)
                if e.getFunction() == "walkingarea"
                for ln in e.getLanes()
            ),
            kerbs=_kerbs(net, crossings),
            crossings=_crossing_shapes(crossings),
            carriageway=_carriageway(net),
            junction_xy=np.array(
                [net.getNode(j).getCoord()[:2] for j in sorted(junctions)], dtype=float
            ).reshape(-1, 2),
            _net=net,
        )

    def path(self, route: tuple[str, ...]) -> np.ndarray:
        """(M, 2) centre-line polyline of the vehicle lanes along ``route`` (edge ids), metres.

        Junction-internal lanes between consecutive edges are included, so turns are curved.
        Cached per route.
        """
        cached = self._paths.get(route)
        if cached is None:
            cached = _route_path(self._net, route)
            self._paths[route] = cached
        return cached


def _pedestrian_only(lane: Lane) -> bool:
    return lane.allows("pedestrian") and not lane.allows("passenger")


def _vehicle_lanes(edge: Edge) -> list[Lane]:
    return [ln for ln in edge.getLanes() if ln.allows("passenger")]


def _unit(v: np.ndarray) -> np.ndarray:
    return v / max(float(np.linalg.norm(v)), 1e-12)


def _kerbs(net: Net, crossings: list[Edge]) -> KerbSegments:
    a, b, inward, idx = [], [], [], []
    for e in net.getEdges(withInternal=False):
        lanes = _vehicle_lanes(e)
        if not lanes or e.getFunction() != "":
            continue
        # the carriageway's outer boundaries: right edge of the rightmost vehicle lane and
        # left edge of the leftmost, offset half a lane width from their centre lines
        for lane, side in ((lanes[0], -1.0), (lanes[-1], 1.0)):
            pts = np.array([p[:2] for p in lane.getShape()], dtype=float)
            for p0, p1 in zip(pts[:-1], pts[1:], strict=True):
                u = _unit(p1 - p0)
                left = np.array([-u[1], u[0]])
                off = side * 0.5 * lane.getWidth() * left
                a.append(p0 + off)
                b.append(p1 + off)
                inward.append(-side * left)
                idx.append(-1)
    for k, c in enumerate(crossings):
        lane = c.getLanes()[0]
        pts = np.array([p[:2] for p in lane.getShape()], dtype=float)
        u = _unit(pts[-1] - pts[0])
        half = 0.5 * lane.getWidth() * np.array([-u[1], u[0]])
        for end, direction in ((pts[0], u), (pts[-1], -u)):
            a.append(end - half)
            b.append(end + half)
            inward.append(direction)
            idx.append(k)
    return KerbSegments(
        np.array(a).reshape(-1, 2),
        np.array(b).reshape(-1, 2),
        np.array(inward).reshape(-1, 2),
        np.array(idx, dtype=int),
    )


def _carriageway(net: Net, extend: float = 15.0) -> shapely.Geometry:
    """Union of the vehicle lanes of the arms, each continued ``extend`` m straight into the
    junction at its junction end (so the junction box is covered but the corners are not)."""
    strips = []
    for e in net.getEdges(withInternal=False):
        for lane in _vehicle_lanes(e):
            pts = np.array([p[:2] for p in lane.getShape()], dtype=float)
            if len(pts) < 2:
                continue
            if e.getToNode().getType() != "dead_end":
                pts = np.vstack([pts, pts[-1] + extend * _unit(pts[-1] - pts[-2])])
            if e.getFromNode().getType() != "dead_end":
                pts = np.vstack([pts[0] - extend * _unit(pts[1] - pts[0]), pts])
            strips.append(shapely.LineString(pts).buffer(0.5 * lane.getWidth(), cap_style="flat"))
    area = shapely.union_all(strips) if strips else shapely.Polygon()
    shapely.prepare(area)
    return area


def _crossing_shapes(crossings: list[Edge]) -> Crossings:
    centre, direction, hl, hw, corners, lanes = [], [], [], [], [], []
    for c in crossings:
        lane = c.getLanes()[0]
        pts = np.array([p[:2] for p in lane.getShape()], dtype=float)
        u = _unit(pts[-1] - pts[0])
        left = np.array([-u[1], u[0]])
        half_l = 0.5 * float(np.linalg.norm(pts[-1] - pts[0]))
        half_w = 0.5 * lane.getWidth()
        mid = 0.5 * (pts[0] + pts[-1])
        centre.append(mid)
        direction.append(u)
        hl.append(half_l)
        hw.append(half_w)
        fwd, side = u * half_l, left * half_w
        corners.append([mid + fwd + side, mid - fwd + side, mid - fwd - side, mid + fwd - side])
        lanes.append(lane.getID())
    return Crossings(
        np.array(centre).reshape(-1, 2),
        np.array(direction).reshape(-1, 2),
        np.array(hl),
        np.array(hw),
        np.array(corners).reshape(-1, 4, 2),
        lanes,
    )


def _route_path(net: Net, route: tuple[str, ...]) -> np.ndarray:
    edges = []
    for eid in route:
        try:
            edges.append(net.getEdge(eid))
        except KeyError:
            raise HiyariError(f"route edge {eid!r} is not in the network") from None
    if not edges:
        raise HiyariError("a vehicle route needs at least one edge")
    # per edge the lane driven on, and between edges the junction-internal lanes
    lanes = [None] * len(edges)
    vias: list[list] = [[] for _ in edges]
    for k in range(1, len(edges)):
        conns = [
            c for c in edges[k - 1].getConnections(edges[k]) if c.getFromLane().allows("passenger")
        ]
        if not conns:
            raise HiyariError(
                f"route has no connection from {edges[k - 1].getID()} to {edges[k].getID()}"
            )
        conn = conns[0]
        lanes[k - 1] = lanes[k - 1] or conn.getFromLane()
        lanes[k] = conn.getToLane()
        via = conn.getViaLaneID()
        while via:
            vl = net.getLane(via)
            vias[k].append(vl)
            nxt = [o for o in vl.getOutgoing() if o.getTo() is edges[k]]
            via = nxt[0].getViaLaneID() if nxt else ""
    if lanes[0] is None:
        drivable = _vehicle_lanes(edges[0]) or edges[0].getLanes()
        lanes[0] = drivable[0]
    pts: list[tuple[float, float]] = []
    for k in range(len(edges)):
        for vl in vias[k]:
            pts += [p[:2] for p in vl.getShape()]
        pts += [p[:2] for p in lanes[k].getShape()]
    arr = np.array(pts, dtype=float)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(arr, axis=0), axis=1) > 1e-6])
    return arr[keep]
