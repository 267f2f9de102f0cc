"""The static road of a run as ASAM OSI: lanes, lane boundaries, stationary objects and traffic
lights, encoded once and spliced into every ``osi3.GroundTruth``.

Sources: lanes and boundaries from the net's :class:`RoadGeometry` (SUMO lane shapes, widths
and the markings derived from lane-change permissions), stationary objects from the static
scene mesh the sensors ray-cast (guard rails, buildings: what occludes), traffic lights from
the run's signal links with their state letters per step.

Choices where OSI leaves room (documented in README "Recording and replay"):

- ids: every static entity has an id from ``STATIC_ID_BASE`` (2^32) upwards, so they never
  collide with moving objects (1, 2, 3 ... in order of appearance).
- Lanes: one OSI lane per SUMO lane (walking areas, which have no centre line, excepted);
  centre lines in the driving direction (``centerline_is_driving_direction``), left / right
  adjacent lanes within the edge, ``source_reference`` (``org.eclipse.sumo.lane``: lane id,
  edge id). Type: driving, intersection (lanes inside junctions), non-driving (bike lanes,
  sidewalks, crossings, verges) with the OpenDRIVE lane type as subtype where the net keeps it.
- Boundaries: one per lane border, shared by the two lanes of an edge that meet there. Type from
  the markings: solid / dashed white line (width 0.15 m); a kerb (0.15 m high) where a
  sidewalk lies beyond the carriageway; road edge at the outer border of an edge; no line
  elsewhere (between sidewalk strips, inside junctions). A carriageway border with both paint
  and a kerb gets both boundaries.
- Stationary objects: one per connected footprint of guard-rail or building triangles in the
  scene mesh, with the footprint as ``base_polygon`` in the object frame (yaw 0, origin at the
  bounding-box centre). Parked cars and other occluding vehicles are SUMO vehicles: OSI
  defines stationary objects as neither vehicles nor traffic lights / signs, so they stay
  moving objects (with zero velocity).
- Traffic lights: one per signal (traffic light id and link index), above the stop line of its
  first incoming lane (4.5 m up; pedestrian signals 2.5 m at the crossing's start); icon
  pedestrian for crossings, none (a full disc) otherwise; colour and mode from SUMO's state
  letter (r/R red, y/Y yellow, g/G/s green, u red-yellow as yellow, o flashing yellow, O off).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from osi3.osi_groundtruth_pb2 import GroundTruth
from osi3.osi_lane_pb2 import Lane as OsiLane
from osi3.osi_lane_pb2 import LaneBoundary
from osi3.osi_object_pb2 import StationaryObject
from osi3.osi_trafficlight_pb2 import TrafficLight

from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.net.road.geometry import Lane, LaneKind, RoadGeometry
from hiyari.traffic.commands import SignalLink

STATIC_ID_BASE = 1 << 32
REF_SUMO_LANE = "org.eclipse.sumo.lane"
REF_SUMO_SIGNAL = "org.eclipse.sumo.tls"
PAINT_WIDTH_M = 0.15
KERB_HEIGHT_M = 0.15
SIGNAL_HEIGHT_M = 4.5  # above the carriageway (Japanese overhead signal clearance)
PEDESTRIAN_SIGNAL_HEIGHT_M = 2.5
SIGNAL_SIZE_M = (0.3, 0.3, 1.2)  # depth, width, height of one signal head

_T = OsiLane.Classification
_B = LaneBoundary.Classification
#: OpenDRIVE lane types (kept by netconvert as SUMO lane types) -> OSI lane subtypes.
_SUBTYPES = {
    "entry": _T.SUBTYPE_ENTRY,
    "exit": _T.SUBTYPE_EXIT,
    "onRamp": _T.SUBTYPE_ONRAMP,
    "offRamp": _T.SUBTYPE_OFFRAMP,
    "connectingRamp": _T.SUBTYPE_CONNECTINGRAMP,
    "parking": _T.SUBTYPE_PARKING,
    "stop": _T.SUBTYPE_STOP,
    "restricted": _T.SUBTYPE_RESTRICTED,
    "shoulder": _T.SUBTYPE_SHOULDER,
    "border": _T.SUBTYPE_BORDER,
    "biking": _T.SUBTYPE_BIKING,
    "sidewalk": _T.SUBTYPE_SIDEWALK,
    "walking": _T.SUBTYPE_SIDEWALK,
}
_KIND_SUBTYPE = {
    LaneKind.BIKE: _T.SUBTYPE_BIKING,
    LaneKind.SIDEWALK: _T.SUBTYPE_SIDEWALK,
    LaneKind.CROSSING: _T.SUBTYPE_OTHER,
    LaneKind.OTHER: _T.SUBTYPE_OTHER,
}
_C = TrafficLight.Classification
#: SUMO signal state letter -> (OSI colour, OSI mode).
SIGNAL_STATES = {
    "r": (_C.COLOR_RED, _C.MODE_CONSTANT),
    "R": (_C.COLOR_RED, _C.MODE_CONSTANT),
    "y": (_C.COLOR_YELLOW, _C.MODE_CONSTANT),
    "Y": (_C.COLOR_YELLOW, _C.MODE_CONSTANT),
    "g": (_C.COLOR_GREEN, _C.MODE_CONSTANT),
    "G": (_C.COLOR_GREEN, _C.MODE_CONSTANT),
    "s": (_C.COLOR_GREEN, _C.MODE_CONSTANT),
    "u": (_C.COLOR_YELLOW, _C.MODE_CONSTANT),
    "o": (_C.COLOR_YELLOW, _C.MODE_FLASHING),
    "O": (_C.COLOR_OTHER, _C.MODE_OFF),
}
_STATIONARY = (
    (Material.BARRIER_METAL, StationaryObject.Classification.TYPE_BARRIER),
    (Material.BUILDING, StationaryObject.Classification.TYPE_BUILDING),
)


def _field_bytes(name: str, message: object) -> bytes:
    """``message`` serialized as one entry of GroundTruth's repeated field ``name``."""
    holder = GroundTruth()
    getattr(holder, name).add().CopyFrom(message)
    return holder.SerializeToString()


@dataclass(frozen=True)
class _Signal:
    tls: str
    index: int
    osi_id: int
    head: TrafficLight  # everything but the colour and mode


class RoadEncoder:
    """Serialized OSI road of one net (:attr:`static`: lanes, boundaries, stationary objects)
    and its traffic lights for any signal state (:meth:`traffic_lights`)."""

    def __init__(
        self,
        geometry: RoadGeometry,
        mesh: SceneMesh | None = None,
        signal_links: Sequence[SignalLink] = (),
    ) -> None:
        self._next = STATIC_ID_BASE
        self.lane_ids: dict[str, int] = {}
        lanes = [ln for ln in geometry.lanes.values() if ln.kind != LaneKind.WALKINGAREA]
        for ln in lanes:
            self.lane_ids[ln.id] = self._id()
        boundaries, sides = self._boundaries(geometry, lanes)
        gt = GroundTruth()
        for b in boundaries:
            gt.lane_boundary.add().CopyFrom(b)
        for ln in lanes:
            gt.lane.add().CopyFrom(self._lane(geometry, ln, sides[ln.id]))
        for obj in stationary_objects(mesh, self._id) if mesh is not None else []:
            gt.stationary_object.add().CopyFrom(obj)
        self.static: bytes = gt.SerializeToString()
        self.counts = {
            "lanes": len(gt.lane),
            "lane_boundaries": len(gt.lane_boundary),
            "stationary_objects": len(gt.stationary_object),
        }
        self._signals = self._signal_heads(geometry, signal_links)
        self.signal_ids = sorted({s.tls for s in self._signals})
        self._light_cache: dict[tuple[int, str], bytes] = {}

    def _id(self) -> int:
        self._next += 1
        return self._next - 1

    # ------------------------------------------------------------------ lanes
    def _lane(self, g: RoadGeometry, ln: Lane, sides: tuple[list[int], list[int]]) -> OsiLane:
        lane = OsiLane()
        lane.id.value = self.lane_ids[ln.id]
        c = lane.classification
        if ln.kind == LaneKind.DRIVING:
            c.type = _T.TYPE_INTERSECTION if ln.internal else _T.TYPE_DRIVING
            c.subtype = _SUBTYPES.get(ln.type, _T.SUBTYPE_NORMAL)
        else:
            c.type = _T.TYPE_NONDRIVING
            c.subtype = _SUBTYPES.get(ln.type, _KIND_SUBTYPE.get(ln.kind, _T.SUBTYPE_OTHER))
        for x, y, z in ln.centre.tolist():
            c.centerline.add(x=x, y=y, z=z)
        c.centerline_is_driving_direction = True
        edge = g.edges.get(ln.edge)
        if edge is not None and not ln.internal:
            by_index = {g.lanes[i].index: i for i in edge.lanes if i in self.lane_ids}
            if ln.index + 1 in by_index:
                c.left_adjacent_lane_id.add(value=self.lane_ids[by_index[ln.index + 1]])
            if ln.index - 1 in by_index:
                c.right_adjacent_lane_id.add(value=self.lane_ids[by_index[ln.index - 1]])
        left, right = sides
        for b in left:
            c.left_lane_boundary_id.add(value=b)
        for b in right:
            c.right_lane_boundary_id.add(value=b)
        lane.source_reference.add(type=REF_SUMO_LANE, identifier=[ln.id, ln.edge])
        return lane

    def _boundary(self, line: np.ndarray, btype: int, painted: bool = False) -> LaneBoundary:
        b = LaneBoundary()
        b.id.value = self._id()
        b.classification.type = btype
        b.classification.color = _B.COLOR_WHITE if painted else _B.COLOR_NONE
        extra = {"width": PAINT_WIDTH_M} if painted else {}
        if btype == _B.TYPE_CURB:
            extra["height"] = KERB_HEIGHT_M
        for x, y, z in line.tolist():
            p = b.boundary_line.add(**extra)
            p.position.x, p.position.y, p.position.z = x, y, z
        return b

    def _boundaries(
        self, g: RoadGeometry, lanes: list[Lane]
    ) -> tuple[list[LaneBoundary], dict[str, tuple[list[int], list[int]]]]:
        """Boundaries and, per lane, its (left, right) boundary ids."""
        paint = {}  # (lane id, "left" / "right") -> marking style
        for m in g.markings:
            side = "right" if m.inset > 0 else "left"
            paint[(m.lane, side)] = m.style
        kerb = {(b.lane, b.side) for b in g.boundaries if b.kerb}
        out: list[LaneBoundary] = []
        sides: dict[str, tuple[list[int], list[int]]] = {ln.id: ([], []) for ln in lanes}

        def add(line: np.ndarray, owners: list[tuple[str, str]], outer: bool) -> None:
            styles = {paint[o] for o in owners if o in paint}
            made = []
            if styles:
                dashed = styles == {"dashed"}
                kind = _B.TYPE_DASHED_LINE if dashed else _B.TYPE_SOLID_LINE
                made.append(self._boundary(line, kind, painted=True))
            if any(o in kerb for o in owners):
                made.append(self._boundary(line, _B.TYPE_CURB))
            if not made:
                made.append(self._boundary(line, _B.TYPE_ROAD_EDGE if outer else _B.TYPE_NO_LINE))
            out.extend(made)
            for lane_id, side in owners:
                sides[lane_id][0 if side == "left" else 1].extend(b.id.value for b in made)

        in_edge = set()
        for edge in g.edges.values():
            if edge.function != "":
                continue
            group = sorted(
                (g.lanes[i] for i in edge.lanes if i in self.lane_ids), key=lambda ln: ln.index
            )
            if not group:
                continue
            in_edge.update(ln.id for ln in group)
            add(group[0].right, [(group[0].id, "right")], outer=True)
            for a, b in zip(group[:-1], group[1:], strict=True):
                if a.left.shape == b.right.shape and np.allclose(a.left, b.right, atol=1e-6):
                    add(a.left, [(a.id, "left"), (b.id, "right")], outer=False)
                else:  # borders not shared (different shapes): one each
                    add(a.left, [(a.id, "left")], outer=False)
                    add(b.right, [(b.id, "right")], outer=False)
            add(group[-1].left, [(group[-1].id, "left")], outer=True)
        for ln in lanes:  # lanes inside junctions: virtual borders
            if ln.id not in in_edge:
                add(ln.left, [(ln.id, "left")], outer=False)
                add(ln.right, [(ln.id, "right")], outer=False)
        return out, sides

    # ------------------------------------------------------------------ signals
    def _signal_heads(self, g: RoadGeometry, links: Sequence[SignalLink]) -> list[_Signal]:
        heads: dict[tuple[str, int], _Signal] = {}
        for link in links:
            k = (link.tls, link.index)
            sig = heads.get(k)
            if sig is None:
                head = _signal_head(g, link)
                if head is None:
                    continue
                sig = heads[k] = _Signal(link.tls, link.index, self._id(), head)
                sig.head.id.value = sig.osi_id
            lane_id = self.lane_ids.get(link.from_lane)
            assigned = {a.value for a in sig.head.classification.assigned_lane_id}
            if lane_id is not None and lane_id not in assigned:
                sig.head.classification.assigned_lane_id.add(value=lane_id)
        return list(heads.values())

    def traffic_lights(self, states: Mapping[str, str]) -> bytes:
        """Serialized GroundTruth ``traffic_light`` entries for SUMO state strings (traffic
        light id -> one letter per link index); lights of unknown ids are left out."""
        parts = []
        for k, sig in enumerate(self._signals):
            state = states.get(sig.tls)
            if state is None or sig.index >= len(state):
                continue
            letter = state[sig.index]
            data = self._light_cache.get((k, letter))
            if data is None:
                light = TrafficLight()
                light.CopyFrom(sig.head)
                colour, mode = SIGNAL_STATES.get(letter, (_C.COLOR_UNKNOWN, _C.MODE_UNKNOWN))
                light.classification.color = colour
                light.classification.mode = mode
                data = self._light_cache[(k, letter)] = _field_bytes("traffic_light", light)
            parts.append(data)
        return b"".join(parts)


def _signal_head(g: RoadGeometry, link: SignalLink) -> TrafficLight | None:
    """A signal head above the stop line of ``link``'s incoming lane (or at its crossing)."""
    to = g.lanes.get(link.to_lane)
    frm = g.lanes.get(link.from_lane)
    light = TrafficLight()
    c = light.classification
    if to is not None and to.kind == LaneKind.CROSSING:
        x, y, z = to.centre[0].tolist()
        z += PEDESTRIAN_SIGNAL_HEIGHT_M
        c.icon = _C.ICON_PEDESTRIAN
        d = to.centre[1] - to.centre[0]
    elif frm is not None:
        x, y, z = frm.centre[-1].tolist()
        z += SIGNAL_HEIGHT_M
        c.icon = _C.ICON_NONE
        d = frm.centre[-1] - frm.centre[-2]
    else:
        return None
    base = light.base
    base.position.x, base.position.y, base.position.z = x, y, z
    # the head faces the traffic it controls
    base.orientation.yaw = float(np.arctan2(-d[1], -d[0]))
    base.dimension.length, base.dimension.width, base.dimension.height = SIGNAL_SIZE_M
    light.source_reference.add(type=REF_SUMO_SIGNAL, identifier=[link.tls, str(link.index)])
    return light


# ---------------------------------------------------------------------- stationary objects
def stationary_objects(mesh: SceneMesh, new_id: Callable[[], int]) -> list[StationaryObject]:
    """One StationaryObject per connected plan-view footprint of the mesh's guard-rail and
    building triangles; ``new_id()`` gives each its id."""
    out = []
    for material, otype in _STATIONARY:
        tri = mesh.vertices[mesh.faces[mesh.material == material]]
        normal_z = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 2]
        tri = tri[np.abs(normal_z) > 1e-9]  # vertical faces add nothing to the footprint
        if len(tri) == 0:
            continue
        footprint = shapely.union_all(shapely.polygons(tri[:, :, :2]))
        parts = [p for p in getattr(footprint, "geoms", [footprint]) if not p.is_empty]
        cx, cy = tri[:, :, 0].mean(axis=1), tri[:, :, 1].mean(axis=1)
        for part in parts:
            xmin, ymin, xmax, ymax = part.bounds
            near = np.flatnonzero((cx >= xmin) & (cx <= xmax) & (cy >= ymin) & (cy <= ymax))
            shapely.prepare(part)
            z = tri[near[shapely.contains_xy(part, cx[near], cy[near])], :, 2]
            if z.size == 0:
                continue
            out.append(_stationary(part.simplify(0.01), float(z.min()), float(z.max()), otype))
            out[-1].id.value = new_id()
    return out


def _stationary(poly: shapely.Polygon, z0: float, z1: float, otype: int) -> StationaryObject:
    obj = StationaryObject()
    xmin, ymin, xmax, ymax = poly.bounds
    cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
    b = obj.base
    b.position.x, b.position.y, b.position.z = cx, cy, (z0 + z1) / 2
    b.orientation.yaw = 0.0
    b.dimension.length, b.dimension.width = xmax - xmin, ymax - ymin
    b.dimension.height = z1 - z0
    for x, y in np.asarray(poly.exterior.coords)[:-1].tolist():
        b.base_polygon.add(x=x - cx, y=y - cy)
    obj.classification.type = otype
    return obj
