"""Road geometry read from any SUMO net: lanes, borders, polygons, junctions, markings, heights.

What it holds: every lane (centre line, left / right borders, polygon, width, kind: driving,
shoulder, bike, sidewalk, crossing, walking area, other; for OpenDRIVE imports the source road,
lane and lane type), edges, junction areas, painted markings
(solid / dashed from lane-change permissions) and road boundaries (carriageway edges, with
or without a kerb), as shapely polygons and numpy (n, 3) arrays.

Frames and units: SUMO network coordinates in metres (x, y, z up), as written in the net (the
net's ``netOffset`` is kept in ``RoadGeometry.offset`` to map back to the source, for example
OpenDRIVE, coordinates: source = net - offset). Left / right are relative to each lane's
direction of travel. Lane index 0 is the rightmost lane of its edge.

Heights: lane centre lines carry SUMO's z. Lane borders take their heights from the lane
centres, interpolated linearly between neighbouring lanes of the same edge (and extrapolated
at the outer borders), so a cross slope written into per-lane heights becomes a plane across
the carriageway. Junction and walking-area outline vertices take their heights from the lane
borders around them (see ``snap_heights``), because netconvert writes them at the node's
height even where lanes are tilted.

Roadside parameters (shoulders, guard rails) come from edge params written by the hiyari
generators: ``hiyari:shoulder_left`` / ``hiyari:shoulder_right`` (metres) and
``hiyari:barrier`` ("left", "right", "left right"). Nets without them have no shoulders and
no rails unless the mesh builder guesses rails (see ``hiyari.net.mesh.road_mesh.MeshParams``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path

import numpy as np
import shapely
from lxml import etree
from scipy.spatial import cKDTree
from shapely.geometry import Polygon
from sumolib.net.lane import SUMO_ROAD_MOTOR_CLASSES, SUMO_VEHICLE_CLASSES

from hiyari.errors import HiyariError
from hiyari.net.road.polylines import Polylines, clean_polyline
from hiyari.net.sumo.files import check_net

#: SUMO's lane width when the net does not give one, m.
SUMO_DEFAULT_LANE_WIDTH = 3.2
#: Horizontal distance within which a junction outline vertex takes a lane border's height, m.
JUNCTION_SNAP = 0.5
#: Other outline vertices: mean height of this many lane border points ...
HEIGHT_NEIGHBOURS = 4
#: ... within this distance in plan, m.
HEIGHT_RADIUS = 10.0

_ALL = frozenset(SUMO_VEHICLE_CLASSES)
_MOTOR = frozenset(SUMO_ROAD_MOTOR_CLASSES)
_WALK = frozenset({"pedestrian", "wheelchair"})
_LIGHT = frozenset({"bicycle", "scooter", "pedestrian", "wheelchair"})
#: Classes of vehicles on duty or scripted: a lane open only to these is closed to traffic.
_ON_DUTY = frozenset({"emergency", "authority", "army", "vip", "custom1", "custom2"})


class LaneKind(StrEnum):
    """What a lane is for, from its edge function and vehicle permissions."""

    DRIVING = "driving"  # motor vehicles allowed
    SHOULDER = "shoulder"  # paved, closed to ordinary traffic (hard shoulder, parking, works)
    BIKE = "bike"  # bicycles (and scooters) but no motor vehicles or only pedestrians
    SIDEWALK = "sidewalk"  # pedestrians only (possibly with bicycles: shared path)
    CROSSING = "crossing"  # pedestrian crossing over a junction
    WALKINGAREA = "walkingarea"  # pedestrian area at a junction corner (polygon)
    OTHER = "other"  # nothing allowed, or rail only (verges, OpenDRIVE border lanes)


def parse_shape(text: str | None) -> np.ndarray:
    """SUMO shape string -> (n, 3) float64 (z = 0 where the shape is 2D)."""
    if not text:
        return np.zeros((0, 3))
    points, commas = len(text.split()), text.count(",")
    if commas == points:  # 2D shape
        xy = np.array(text.replace(",", " ").split(), dtype=np.float64).reshape(-1, 2)
        return np.column_stack([xy, np.zeros(len(xy))])
    if commas == 2 * points:
        flat = text.replace(",", " ")
    else:  # SUMO leaves z out of points where it is 0, even within a 3D shape
        flat = " ".join(t if t.count(",") == 2 else t + ",0" for t in text.split())
        flat = flat.replace(",", " ")
    return np.array(flat.split(), dtype=np.float64).reshape(-1, 3)


def permissions(allow: str | None, disallow: str | None) -> frozenset[str]:
    """Vehicle classes allowed on a lane from SUMO's allow / disallow attributes."""
    if allow is not None:
        tokens = set(allow.split())
        return _ALL if "all" in tokens else frozenset(tokens)
    if disallow is not None:
        tokens = set(disallow.split())
        return frozenset() if "all" in tokens else _ALL - tokens
    return _ALL


def lane_kind(function: str, allowed: frozenset[str]) -> LaneKind:
    """Classify a lane: crossings and walking areas by edge function, others by permissions."""
    if function == "crossing":
        return LaneKind.CROSSING
    if function == "walkingarea":
        return LaneKind.WALKINGAREA
    if allowed & _MOTOR:
        return LaneKind.DRIVING
    if allowed and allowed <= _ON_DUTY:
        return LaneKind.SHOULDER
    if allowed and allowed <= _LIGHT:
        return LaneKind.SIDEWALK if "pedestrian" in allowed else LaneKind.BIKE
    if allowed & _WALK:
        return LaneKind.SIDEWALK
    return LaneKind.OTHER


def _may_change(attr: str | None) -> bool:
    """Whether passenger cars may change lanes across this side (changeLeft / changeRight)."""
    return attr is None or "passenger" in permissions(attr, None)


@dataclass(frozen=True, eq=False)
class Lane:
    """One SUMO lane. ``centre``, ``left`` and ``right`` are (n, 3) polylines in metres.

    For walking areas ``centre`` is the area's outline and ``left``/``right`` repeat it.
    ``length`` is SUMO's lane length (3D), ``width`` SUMO's lane width.
    ``odr_road`` / ``odr_lane`` / ``odr_type``: the OpenDRIVE road id, lane id and lane type
    the lane was imported from (the net's ``origId`` param, "<road>_<lane>", and lane type;
    the first source where netconvert joined several); "", None, "" for other nets.
    """

    id: str
    edge: str
    index: int
    kind: LaneKind
    type: str  # SUMO lane type attribute (OpenDRIVE lane type on imports), "" if none
    width: float
    length: float
    speed: float
    allowed: frozenset[str]
    change_left: bool  # passenger cars may change to the left lane
    change_right: bool
    internal: bool  # lane inside a junction (edge function internal / crossing / walkingarea)
    centre: np.ndarray
    left: np.ndarray
    right: np.ndarray
    polygon: Polygon  # plan-view outline (2D)
    odr_road: str = ""
    odr_lane: int | None = None
    odr_type: str = ""

    @property
    def heights(self) -> np.ndarray:
        """(n,) z of the centre line, m."""
        return self.centre[:, 2]


@dataclass(frozen=True, eq=False)
class Edge:
    """One SUMO edge with its lanes (ids by index) and roadside parameters."""

    id: str
    function: str  # "" for normal edges, else internal / crossing / walkingarea
    from_node: str
    to_node: str
    lanes: tuple[str, ...]
    params: dict[str, str] = field(default_factory=dict)

    @property
    def shoulder_left(self) -> float:
        """Paved shoulder beyond the leftmost lane, m."""
        return float(self.params.get("hiyari:shoulder_left", 0.0))

    @property
    def shoulder_right(self) -> float:
        """Paved shoulder beyond the rightmost lane, m."""
        return float(self.params.get("hiyari:shoulder_right", 0.0))

    @property
    def barriers(self) -> frozenset[str] | None:
        """Sides with a guard rail ("left", "right"; "none" for none); None if the net does not say."""
        text = self.params.get("hiyari:barrier")
        return None if text is None else frozenset(text.split())


@dataclass(frozen=True, eq=False)
class Junction:
    """A junction area: outline (n, 3) metres and its plan-view polygon.

    The polygon is as netconvert drew it: empty at dead ends (the outline is a line across
    the lane ends) and occasionally self-intersecting (the mesh builder repairs it).
    """

    id: str
    type: str
    outline: np.ndarray
    polygon: Polygon


@dataclass(frozen=True, eq=False)
class LaneMarking:
    """A painted line along a lane border.

    ``line`` is the border (n, 3) in the lane's direction. ``inset`` says where the paint
    lies: 0 centred on the border (between two lanes), +1 entirely left of it (the right edge
    line of a carriageway), -1 entirely right of it (the left edge / centre line).
    ``style`` is "dashed" where passenger cars may change lanes across it in both directions
    (and both lanes are of the same type), else "solid".
    """

    edge: str
    lane: str
    line: np.ndarray
    style: str
    inset: int
    speed: float  # lane speed limit, m/s (selects the dash pattern)


@dataclass(frozen=True, eq=False)
class RoadBoundary:
    """An outer edge of a carriageway (its driving and bike lanes) on one side of an edge.

    ``line`` is the outer border of the outermost carriageway lane, in the direction of
    travel. ``kerb``: a sidewalk lies beyond it; ``outermost``: no other lane of the edge
    lies beyond it (where shoulders and guard rails can go).
    """

    edge: str
    lane: str
    side: str  # "left" or "right"
    line: np.ndarray
    kerb: bool
    outermost: bool


@dataclass(frozen=True, eq=False)
class RoadGeometry:
    """Everything static about the roads of one SUMO net."""

    path: Path
    offset: np.ndarray  # (2,) netOffset: net coordinates = source coordinates + offset
    lanes: dict[str, Lane]
    edges: dict[str, Edge]
    junctions: dict[str, Junction]
    markings: list[LaneMarking]
    boundaries: list[RoadBoundary]

    @staticmethod
    def from_net(path: str | Path) -> RoadGeometry:
        """Read a SUMO .net.xml; HiyariError (one line) if unreadable or without drivable lanes."""
        root = check_net(path)
        return _read(Path(path), root)

    def lanes_of(self, *kinds: LaneKind, internal: bool = False) -> list[Lane]:
        """Lanes of the given kinds, normal edges only unless ``internal``."""
        return [
            ln for ln in self.lanes.values() if ln.kind in kinds and (internal or not ln.internal)
        ]

    @property
    def driving_lanes(self) -> list[Lane]:
        """Lanes of normal edges where motor vehicles may drive."""
        return self.lanes_of(LaneKind.DRIVING)

    @property
    def sidewalks(self) -> list[Lane]:
        """Pedestrian lanes of normal edges."""
        return self.lanes_of(LaneKind.SIDEWALK)

    @property
    def crossings(self) -> list[Lane]:
        """Pedestrian crossings (lanes of crossing edges inside junctions)."""
        return self.lanes_of(LaneKind.CROSSING, internal=True)

    @property
    def walking_areas(self) -> list[Lane]:
        """Walking areas at junction corners (``centre`` is the outline)."""
        return self.lanes_of(LaneKind.WALKINGAREA, internal=True)

    def bounds(self) -> tuple[float, float, float, float, float, float]:
        """(xmin, ymin, zmin, xmax, ymax, zmax) over all lane borders and junctions, m."""
        pts = [ln.left for ln in self.lanes.values()] + [ln.right for ln in self.lanes.values()]
        pts += [j.outline for j in self.junctions.values() if len(j.outline)]
        allp = np.concatenate(pts)
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        return (*lo.tolist(), *hi.tolist())


def _read(path: Path, root: etree._Element) -> RoadGeometry:
    loc = root.find("location")
    offset = np.zeros(2)
    if loc is not None and loc.get("netOffset"):
        offset = np.array(loc.get("netOffset").split(",")[:2], dtype=np.float64)
    raw: list[dict] = []
    edges: dict[str, Edge] = {}
    for e in root.iter("edge"):
        eid = e.get("id")
        function = e.get("function", "")
        params = {p.get("key"): p.get("value", "") for p in e.findall("param")}
        lane_ids = []
        for ln in e.iter("lane"):
            centre = parse_shape(ln.get("shape"))
            if function != "walkingarea":
                centre = clean_polyline(centre)
            if len(centre) < 2:
                continue  # zero-length internal lanes carry no area
            allowed = permissions(ln.get("allow"), ln.get("disallow"))
            odr_road, odr_lane = _origin(ln)
            raw.append(
                {
                    "id": ln.get("id"),
                    "edge": eid,
                    "index": int(ln.get("index", 0)),
                    "kind": lane_kind(function, allowed),
                    "type": ln.get("type", ""),
                    "width": float(ln.get("width", SUMO_DEFAULT_LANE_WIDTH)),
                    "length": float(ln.get("length", 0.0)),
                    "speed": float(ln.get("speed", 0.0)),
                    "allowed": allowed,
                    "change_left": _may_change(ln.get("changeLeft")),
                    "change_right": _may_change(ln.get("changeRight")),
                    "internal": function != "",
                    "centre": centre,
                    "odr_road": odr_road,
                    "odr_lane": odr_lane,
                    "odr_type": ln.get("type", "") if odr_road else "",
                }
            )
            lane_ids.append(ln.get("id"))
        edges[eid] = Edge(
            eid, function, e.get("from", ""), e.get("to", ""), tuple(lane_ids), params
        )
    if not raw:
        raise HiyariError(f"{path}: network has no lanes with a shape")
    _borders(raw, edges)
    strips = [r for r in raw if r["kind"] != LaneKind.WALKINGAREA]
    outlines = [np.concatenate([r["right"][:, :2], r["left"][::-1, :2]]) for r in strips]
    index = np.repeat(np.arange(len(outlines)), [len(o) for o in outlines])
    polygons = shapely.polygons(shapely.linearrings(np.concatenate(outlines), indices=index))
    lanes = {r["id"]: _make_lane(r, poly) for r, poly in zip(strips, polygons, strict=True)}
    exact = _border_points(ln for ln in lanes.values() if not ln.internal)
    nearby = _border_points(lanes.values())
    walking = [r for r in raw if r["kind"] == LaneKind.WALKINGAREA]
    outlines = snap_heights([r["centre"] for r in walking], exact, nearby)
    for r, outline in zip(walking, outlines, strict=True):
        r["centre"] = r["left"] = r["right"] = outline
        lanes[r["id"]] = _make_lane(r, Polygon(outline[:, :2]) if len(outline) >= 3 else Polygon())
    junctions = _junctions(root, exact, nearby)
    markings = _markings(lanes, edges)
    boundaries = _boundaries(lanes, edges)
    return RoadGeometry(path, offset, lanes, edges, junctions, markings, boundaries)


def _borders(raw: list[dict], edges: dict[str, Edge]) -> None:
    """Add 'left' and 'right' borders to each raw lane (vectorised over all lanes)."""
    strips = [r for r in raw if r["kind"] != LaneKind.WALKINGAREA]
    for r in raw:
        if r["kind"] == LaneKind.WALKINGAREA:
            r["left"] = r["right"] = r["centre"]
    if not strips:
        return
    lines = Polylines.pack([r["centre"] for r in strips])
    normals = lines.left_normals()
    half = np.repeat([r["width"] / 2 for r in strips], np.diff(lines.offsets))
    left = lines.offset(half, normals)
    right = lines.offset(-half, normals)
    for k, r in enumerate(strips):
        a, b = lines.offsets[k], lines.offsets[k + 1]
        r["left"], r["right"] = left[a:b], right[a:b]
    by_id = {r["id"]: r for r in strips}
    for edge in edges.values():
        if edge.function not in ("", "internal"):
            continue
        group = sorted((by_id[i] for i in edge.lanes if i in by_id), key=lambda r: r["index"])
        _share_borders(group)


def _share_borders(group: list[dict]) -> None:
    """Make neighbouring lanes of one edge share their common border, heights interpolated."""
    if len(group) < 2 or len({len(r["centre"]) for r in group}) != 1:
        return
    z = np.stack([r["centre"][:, 2] for r in group])  # (lanes, n), right to left
    w = np.array([r["width"] for r in group])[:, None]
    for a, b in zip(group[:-1], group[1:], strict=True):
        shared = 0.5 * (a["left"] + b["right"])
        a["left"] = shared
        b["right"] = shared.copy()
    # Heights: linear across the edge through the lane centres (a cross slope becomes a plane).
    zb = z[:-1] + (z[1:] - z[:-1]) * w[:-1] / (w[:-1] + w[1:])
    slope_right = (z[1] - z[0]) / ((w[0] + w[1]) / 2)
    slope_left = (z[-1] - z[-2]) / ((w[-1] + w[-2]) / 2)
    group[0]["right"][:, 2] = z[0] - slope_right * w[0, 0] / 2
    group[-1]["left"][:, 2] = z[-1] + slope_left * w[-1, 0] / 2
    for k in range(len(group) - 1):
        group[k]["left"][:, 2] = zb[k]
        group[k + 1]["right"][:, 2] = zb[k]


def _make_lane(r: dict, poly: Polygon) -> Lane:
    return Lane(
        id=r["id"],
        edge=r["edge"],
        index=r["index"],
        kind=r["kind"],
        type=r["type"],
        width=r["width"],
        length=r["length"],
        speed=r["speed"],
        allowed=r["allowed"],
        change_left=r["change_left"],
        change_right=r["change_right"],
        internal=r["internal"],
        centre=r["centre"],
        left=r["left"],
        right=r["right"],
        polygon=poly,
        odr_road=r["odr_road"],
        odr_lane=r["odr_lane"],
        odr_type=r["odr_type"],
    )


def _origin(lane: etree._Element) -> tuple[str, int | None]:
    """OpenDRIVE (road id, lane id) from a lane's ``origId`` param ("" and None if none)."""
    for p in lane.iter("param"):
        if p.get("key") == "origId":
            road, _, lane_id = (p.get("value") or "").split(" ")[0].rpartition("_")
            try:
                return road, int(lane_id)
            except ValueError:
                return "", None
    return "", None


def _border_points(lanes: Iterable[Lane]) -> np.ndarray:
    """(P, 3) all left and right border points of the given lanes."""
    parts = [np.concatenate([ln.left, ln.right]) for ln in lanes]
    return np.concatenate(parts) if parts else np.zeros((0, 3))


def snap_heights(
    outlines: list[np.ndarray], exact: np.ndarray, nearby: np.ndarray
) -> list[np.ndarray]:
    """Outlines whose vertex heights follow the lanes around them.

    A vertex within ``JUNCTION_SNAP`` metres (in plan) of a point of ``exact`` (normal-lane
    borders) takes that point's z. Any other vertex takes the inverse-distance mean z of the
    ``HEIGHT_NEIGHBOURS`` points of ``nearby`` (all lane borders) nearest to it within
    ``HEIGHT_RADIUS`` metres in plan, or keeps its z when there are none. Neighbours are
    searched in 3D, so a road passing above or below is not taken.
    """
    if not outlines:
        return outlines
    flat = np.concatenate(outlines).copy()
    done = np.zeros(len(flat), dtype=bool)
    if len(exact):
        _, idx = cKDTree(exact).query(flat)
        done = np.hypot(*(exact[idx, :2] - flat[:, :2]).T) <= JUNCTION_SNAP
        flat[done, 2] = exact[idx[done], 2]
    rest = np.flatnonzero(~done)
    if len(nearby) and len(rest):
        k = min(HEIGHT_NEIGHBOURS, len(nearby))
        _, idx = cKDTree(nearby).query(flat[rest], k=k)
        idx = idx.reshape(len(rest), k)
        plan = np.hypot(*(nearby[idx, :2] - flat[rest, None, :2]).transpose(2, 0, 1))
        weight = np.where(plan <= HEIGHT_RADIUS, 1.0 / np.maximum(plan, 1e-3), 0.0)
        total = weight.sum(axis=1)
        have = total > 0
        z = (weight * nearby[idx, 2]).sum(axis=1) / np.where(have, total, 1.0)
        flat[rest[have], 2] = z[have]
    return np.split(flat, np.cumsum([len(o) for o in outlines])[:-1])


def _junctions(root: etree._Element, exact: np.ndarray, nearby: np.ndarray) -> dict[str, Junction]:
    found = []
    for j in root.iter("junction"):
        if j.get("type") == "internal":
            continue
        outline = parse_shape(j.get("shape"))
        if len(outline) > 1 and np.allclose(outline[0], outline[-1]):
            outline = outline[:-1]
        if len(outline) < 2:
            continue
        found.append((j.get("id"), j.get("type", ""), outline))
    snapped = snap_heights([f[2] for f in found], exact, nearby)
    return {
        jid: Junction(
            jid, jtype, outline, Polygon(outline[:, :2]) if len(outline) > 2 else Polygon()
        )
        for (jid, jtype, _), outline in zip(found, snapped, strict=True)
    }


def _markings(lanes: dict[str, Lane], edges: dict[str, Edge]) -> list[LaneMarking]:
    carriageway = (LaneKind.DRIVING, LaneKind.BIKE)
    out: list[LaneMarking] = []
    for edge in edges.values():
        if edge.function != "":
            continue
        group = sorted(
            (lanes[i] for i in edge.lanes if i in lanes and lanes[i].kind in carriageway),
            key=lambda ln: ln.index,
        )
        if not group:
            continue
        first, last = group[0], group[-1]
        out.append(LaneMarking(edge.id, first.id, first.right, "solid", +1, first.speed))
        out.append(LaneMarking(edge.id, last.id, last.left, "solid", -1, last.speed))
        for a, b in zip(group[:-1], group[1:], strict=True):
            if b.index != a.index + 1:
                continue
            dashed = a.change_left and b.change_right and a.type == b.type and a.kind == b.kind
            out.append(
                LaneMarking(edge.id, a.id, a.left, "dashed" if dashed else "solid", 0, a.speed)
            )
    return out


def _boundaries(lanes: dict[str, Lane], edges: dict[str, Edge]) -> list[RoadBoundary]:
    out = []
    for edge in edges.values():
        if edge.function != "":
            continue
        group = sorted((lanes[i] for i in edge.lanes if i in lanes), key=lambda ln: ln.index)
        road = [k for k, ln in enumerate(group) if ln.kind in (LaneKind.DRIVING, LaneKind.BIKE)]
        if not road:
            continue
        first, last = road[0], road[-1]
        beyond_right, beyond_left = group[:first], group[last + 1 :]
        out.append(
            RoadBoundary(
                edge.id,
                group[first].id,
                "right",
                group[first].right,
                any(ln.kind == LaneKind.SIDEWALK for ln in beyond_right),
                not beyond_right,
            )
        )
        out.append(
            RoadBoundary(
                edge.id,
                group[last].id,
                "left",
                group[last].left,
                any(ln.kind == LaneKind.SIDEWALK for ln in beyond_left),
                not beyond_left,
            )
        )
    return out
