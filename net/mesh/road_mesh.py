"""The static 3D road scene: triangles with one material each, built from a RoadGeometry.

Parts (material):
- lane surfaces of normal and internal lanes, so vehicles drive on the heights SUMO gives
  them, in the material of their OpenDRIVE lane type from the one lane-type table
  (``hiyari.net.sumo.lane_types``: asphalt for driving lanes and shoulders, grass for
  borders and medians, concrete for curbs; asphalt for lanes of other nets); paved shoulders
  from edge params (asphalt); junction areas just below the lanes (asphalt: the rest of the
  junction between and around its lanes);
- lane markings: solid / dashed lines and zebra crossings, raised ``marking_lift`` above the
  surface (lane paint);
- sidewalks and walking areas as closed solids standing ``kerb_height`` above the road, whose
  road-side faces are the kerbs (concrete);
- guard rails as closed beams beside the shoulders (barrier metal);
- mapped buildings (an OpenStreetMap import's footprints and heights, hiyari.net.road.buildings)
  as closed prisms standing on the ground at the nearest road height (building);
- optional generated buildings on the city blocks of a net without mapped ones (building) and
  a ground plane (grass).

Surfaces face up; solids are closed with outward faces. Coordinates are SUMO network metres,
z up. The mesh builder is vectorised over lanes: each part is one numpy pass over all
polylines of that kind.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.spatial import cKDTree
from shapely.geometry import box

from hiyari.net.mesh.export import export_mesh
from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.primitives import (
    PolygonSet,
    border_prism,
    polygon_prism,
    polygon_sheet,
    strip,
)
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.net.road.buildings import Building
from hiyari.net.road.geometry import Edge, Lane, LaneKind, RoadGeometry
from hiyari.net.road.network import RoadNetwork
from hiyari.net.road.polylines import Polylines
from hiyari.net.sumo.lane_types import LANE_TYPES, lane_type

__all__ = ["MeshParams", "build_scene_mesh", "export_mesh", "network_scene_mesh"]


@dataclass(frozen=True)
class MeshParams:
    """Dimensions of the scene's parts (metres, m/s); defaults are typical Japanese values."""

    kerb_height: float = 0.15  # sidewalk top above the road
    marking_width: float = 0.15  # lane lines
    marking_lift: float = 0.005  # paint above the surface
    dash_length: float = 5.0  # lane boundary dashes on general roads
    dash_gap: float = 5.0
    dash_length_fast: float = 8.0  # on lanes faster than ``fast_speed`` (expressways)
    dash_gap_fast: float = 12.0
    fast_speed: float = 16.7  # 60 km/h
    zebra_stripe: float = 0.45  # crossing bars along the crossing's path
    zebra_gap: float = 0.45
    barrier_offset: float = 0.5  # rail centre beyond the shoulder edge
    barrier_bottom: float = 0.3  # rail beam from this height above the surface ...
    barrier_top: float = 0.8  # ... to this height
    barrier_thickness: float = 0.1
    guess_barriers: bool = True  # nets without hiyari:barrier params: rails on fast roads
    barrier_speed: float = 22.2  # guessed rails on the right of edges this fast (80 km/h)
    bridge_distance: float = 25.0  # longest junction a shoulder / rail is continued across
    junction_drop: float = 0.01  # junction areas lie this far below the lanes crossing them
    junction_overlap: float = 0.05  # ... and reach this far under the lanes ending at them
    ground: bool = True  # grass plane under the whole network
    ground_margin: float = 50.0
    ground_drop: float = 0.05  # below the lowest road point
    building_setback: float = 3.0  # from the block edge (sidewalk back)
    building_lot: float = 30.0  # lot grid size within a block
    building_gap: float = 4.0  # between neighbouring buildings
    building_min_area: float = 60.0
    building_height_min: float = 8.0
    building_height_max: float = 40.0
    seed: int = 0  # building heights


def build_scene_mesh(
    geometry: RoadGeometry,
    buildings: bool = False,
    params: MeshParams | None = None,
    mapped: Sequence[Building] = (),
) -> SceneMesh:
    """Triangulate the road scene of ``geometry`` (see the module docstring for the parts):
    ``mapped`` buildings as given, generated ones on the blocks with ``buildings``."""
    p = params or MeshParams()
    parts = [
        _surfaces(geometry, p),
        _junctions(geometry, p),
        _roadside(geometry, p),
        _markings(geometry, p),
        _crossings(geometry, p),
        _pedestrian_solids(geometry, p),
        _mapped_buildings(geometry, mapped),
    ]
    if buildings:
        parts.append(_buildings(geometry, p))
    if p.ground:
        parts.append(_ground(geometry, p))
    return _drop_degenerate(SceneMesh.concatenate(parts))


def network_scene_mesh(
    network: RoadNetwork, buildings: bool = False, params: MeshParams | None = None
) -> SceneMesh:
    """The scene of a run's road: its geometry with its mapped buildings; ``buildings`` adds
    generated ones only to a net that has none mapped (they would stand in the real ones)."""
    mapped = network.buildings
    return build_scene_mesh(network.geometry, buildings and not mapped, params, mapped)


def _strip_of(lanes: list[Lane], material: Material) -> SceneMesh:
    """Each lane's surface between its borders."""
    if not lanes:
        return SceneMesh.concatenate([])
    lines = Polylines.pack([ln.centre for ln in lanes])
    left = np.concatenate([ln.left for ln in lanes])
    right = np.concatenate([ln.right for ln in lanes])
    return strip(left, right, lines, material)


def surface_material(lane: Lane) -> Material:
    """The material of a lane's surface: its OpenDRIVE lane type's in the lane-type table
    (grass for types the table does not know), asphalt for lanes of other nets."""
    if lane.odr_type:
        entry = lane_type(lane.odr_type)
    elif (entry := LANE_TYPES.get(lane.type)) is None:
        return Material.ASPHALT
    return Material[entry.surface.name]


def _surfaces(g: RoadGeometry, p: MeshParams) -> SceneMesh:
    road_kinds = (LaneKind.DRIVING, LaneKind.SHOULDER, LaneKind.BIKE, LaneKind.OTHER)
    lanes = g.lanes_of(*road_kinds) + [
        ln for ln in g.lanes_of(*road_kinds, internal=True) if ln.internal
    ]
    by_material: dict[Material, list[Lane]] = {}
    for ln in lanes:
        by_material.setdefault(surface_material(ln), []).append(ln)
    return SceneMesh.concatenate([_strip_of(by_material[m], m) for m in sorted(by_material)])


def _junctions(g: RoadGeometry, p: MeshParams) -> SceneMesh:
    polys = PolygonSet.from_outlines(
        [j.outline for j in g.junctions.values()], grow=p.junction_overlap
    )
    return polygon_sheet(polys, -p.junction_drop, Material.ASPHALT)


@dataclass(frozen=True, eq=False)
class _Side:
    """One outer side of a carriageway: the outer lane's centre line and border, per point."""

    from_node: str
    to_node: str
    sign: float  # +1: the left side of the lane, -1: the right side
    centre: np.ndarray  # (n, 3)
    border: np.ndarray  # (n, 3) the lane's outer border
    half: np.ndarray  # (n,) half lane width
    shoulder: np.ndarray  # (n,) shoulder width
    rail: bool

    def extended(self, nxt: _Side) -> _Side:
        """This side continued to the first point of ``nxt`` (bridging a junction)."""
        return _Side(
            self.from_node,
            self.to_node,
            self.sign,
            np.concatenate([self.centre, nxt.centre[:1]]),
            np.concatenate([self.border, nxt.border[:1]]),
            np.concatenate([self.half, nxt.half[:1]]),
            np.concatenate([self.shoulder, nxt.shoulder[:1]]),
            self.rail,
        )


def _side(edge: Edge, lane: Lane, sign: float, shoulder: float, rail: bool) -> _Side:
    n = len(lane.centre)
    return _Side(
        edge.from_node,
        edge.to_node,
        sign,
        lane.centre,
        lane.left if sign > 0 else lane.right,
        np.full(n, lane.width / 2),
        np.full(n, shoulder),
        rail,
    )


def _sides(g: RoadGeometry, p: MeshParams) -> list[_Side]:
    """Outer sides of every carriageway, each continued across the junction that follows it.

    A side is continued to the start of the same side of the next edge (the one whose start
    is nearest, within ``p.bridge_distance``), so shoulders and rails run through the short
    junctions between consecutive edges instead of stopping at them.
    """
    explicit = any(e.barriers is not None for e in g.edges.values())
    sides: list[_Side] = []
    for b in g.boundaries:
        if not b.outermost:
            continue
        edge, lane = g.edges[b.edge], g.lanes[b.lane]
        rails = edge.barriers
        if rails is None:
            speed = max(g.lanes[i].speed for i in edge.lanes if i in g.lanes)
            guess = p.guess_barriers and not explicit and speed >= p.barrier_speed
            rails = frozenset({"right"}) if guess else frozenset()
        shoulder = edge.shoulder_right if b.side == "right" else edge.shoulder_left
        sign = -1.0 if b.side == "right" else 1.0
        sides.append(_side(edge, lane, sign, shoulder, b.side in rails))
    starts: dict[tuple[str, float], list[_Side]] = {}
    for s in sides:
        starts.setdefault((s.from_node, s.sign), []).append(s)
    out = []
    for s in sides:
        nxt = [
            c
            for c in starts.get((s.to_node, s.sign), [])
            if c.rail == s.rail and c.to_node != s.from_node
        ]
        if nxt:
            gaps = [np.linalg.norm(c.border[0] - s.border[-1]) for c in nxt]
            best = int(np.argmin(gaps))
            if 0.01 < gaps[best] <= p.bridge_distance:  # nothing to bridge when they touch
                s = s.extended(nxt[best])
        out.append(s)
    return [s for s in out if s.rail or s.shoulder.max() > 0]


def _roadside(g: RoadGeometry, p: MeshParams) -> SceneMesh:
    """Paved shoulders and guard rails beyond the outer lanes, on the carriageway's slope."""
    sides = _sides(g, p)
    if not sides:
        return SceneMesh.concatenate([])
    lines = Polylines.pack([s.centre for s in sides])
    normals = lines.left_normals()
    counts = np.diff(lines.offsets)
    sign = np.repeat([s.sign for s in sides], counts)
    half = np.concatenate([s.half for s in sides])
    shoulder = np.concatenate([s.shoulder for s in sides])
    border = np.concatenate([s.border for s in sides])
    # Lane tilt outwards (dz per metre away from the lane centre), extrapolated beyond it.
    slope = (border[:, 2] - lines.points[:, 2]) / half

    def at(distance: np.ndarray) -> np.ndarray:
        pts = lines.offset(sign * (half + distance), normals)
        pts[:, 2] = border[:, 2] + slope * distance
        return pts

    def sub(mask: np.ndarray) -> tuple[np.ndarray, Polylines]:
        return np.repeat(mask, counts), Polylines.pack(
            [lines.line(k) for k in np.flatnonzero(mask)]
        )

    parts = []
    has_shoulder = np.array([s.shoulder.max() > 0 for s in sides])
    if has_shoulder.any():
        outer = at(shoulder)
        left = np.where((sign > 0)[:, None], outer, border)
        right = np.where((sign > 0)[:, None], border, outer)
        keep, lines_s = sub(has_shoulder)
        parts.append(strip(left[keep], right[keep], lines_s, Material.ASPHALT))
    has_rail = np.array([s.rail for s in sides])
    if has_rail.any():
        t = p.barrier_thickness / 2
        near, far = at(shoulder + p.barrier_offset - t), at(shoulder + p.barrier_offset + t)
        left = np.where((sign > 0)[:, None], far, near)
        right = np.where((sign > 0)[:, None], near, far)
        keep, lines_r = sub(has_rail)
        parts.append(
            border_prism(
                left[keep],
                right[keep],
                lines_r,
                p.barrier_bottom,
                p.barrier_top,
                Material.BARRIER_METAL,
            )
        )
    return SceneMesh.concatenate(parts)


def _paint(
    lines: Polylines,
    tilt: np.ndarray,
    centre_shift: np.ndarray,
    width: np.ndarray,
    lift: float,
) -> SceneMesh:
    """Paint strips along ``lines``: ``width`` wide, centred ``centre_shift`` to the left.

    ``tilt`` is the surface's dz per metre to the left at each point; all three are per
    point (P,).
    """
    normals = lines.left_normals()
    lo, hi = centre_shift - width / 2, centre_shift + width / 2
    left = lines.offset(hi, normals)
    right = lines.offset(lo, normals)
    left[:, 2] += tilt * hi + lift
    right[:, 2] += tilt * lo + lift
    return strip(left, right, lines, Material.LANE_PAINT)


def _markings(g: RoadGeometry, p: MeshParams) -> SceneMesh:
    if not g.markings:
        return SceneMesh.concatenate([])
    lines = Polylines.pack([m.line for m in g.markings])
    counts = np.diff(lines.offsets)
    lanes = [g.lanes[m.lane] for m in g.markings]
    tilt = np.concatenate([(ln.left[:, 2] - ln.right[:, 2]) / ln.width for ln in lanes])
    inset = np.array([m.inset for m in g.markings], dtype=np.float64)
    dashed = np.array([m.style == "dashed" for m in g.markings])
    fast = np.array([m.speed > p.fast_speed for m in g.markings])
    mw = p.marking_width
    parts = []
    solid_idx = np.flatnonzero(~dashed)
    if solid_idx.size:
        keep = np.repeat(~dashed, counts)
        sub = Polylines.pack([lines.line(k) for k in solid_idx])
        shift = np.repeat(inset[solid_idx] * mw / 2, np.diff(sub.offsets))
        parts.append(_paint(sub, tilt[keep], shift, np.full(len(shift), mw), p.marking_lift))
    dash_idx = np.flatnonzero(dashed)
    if dash_idx.size:
        keep = np.repeat(dashed, counts)
        sub = Polylines.pack([lines.line(k) for k in dash_idx])
        f = fast[dash_idx]
        dash = np.where(f, p.dash_length_fast, p.dash_length)
        gap = np.where(f, p.dash_gap_fast, p.dash_gap)
        pieces, source, sub_tilt = sub.dashes(dash, gap, tilt[keep][:, None])
        if len(pieces):
            shift = np.repeat(inset[dash_idx][source] * mw / 2, np.diff(pieces.offsets))
            parts.append(
                _paint(pieces, sub_tilt[:, 0], shift, np.full(len(shift), mw), p.marking_lift)
            )
    return SceneMesh.concatenate(parts)


def _crossings(g: RoadGeometry, p: MeshParams) -> SceneMesh:
    """Zebra bars across each crossing's path, as wide as the crossing."""
    lanes = g.crossings
    if not lanes:
        return SceneMesh.concatenate([])
    lines = Polylines.pack([ln.centre for ln in lanes])
    n = len(lines)
    pieces, source, _ = lines.dashes(np.full(n, p.zebra_stripe), np.full(n, p.zebra_gap))
    if not len(pieces):
        return SceneMesh.concatenate([])
    width = np.repeat([lanes[k].width for k in source], np.diff(pieces.offsets))
    zeros = np.zeros(len(width))
    return _paint(pieces, zeros, zeros, width, p.marking_lift)


def _pedestrian_solids(g: RoadGeometry, p: MeshParams) -> SceneMesh:
    """Sidewalks and walking areas raised by the kerb height, as closed solids."""
    parts = []
    walks = g.sidewalks
    if walks:
        lines = Polylines.pack([ln.centre for ln in walks])
        left = np.concatenate([ln.left for ln in walks])
        right = np.concatenate([ln.right for ln in walks])
        parts.append(border_prism(left, right, lines, 0.0, p.kerb_height, Material.CONCRETE))
    areas = PolygonSet.from_outlines([ln.centre for ln in g.walking_areas])
    if len(areas):
        z = areas.rings[:, 2]
        parts.append(polygon_prism(areas, z, z + p.kerb_height, Material.CONCRETE))
    return SceneMesh.concatenate(parts)


def _road_footprint(g: RoadGeometry):
    """Union of the carriageways with their sidewalks, junctions and walking areas."""
    outlines = []
    for edge in g.edges.values():
        lanes = sorted((g.lanes[i] for i in edge.lanes if i in g.lanes), key=lambda ln: ln.index)
        if edge.function == "" and lanes:
            outlines.append(np.concatenate([lanes[0].right, lanes[-1].left[::-1]]))
    outlines += [j.outline for j in g.junctions.values()]
    outlines += [ln.centre for ln in g.walking_areas]
    polys = PolygonSet.from_outlines(outlines, min_area=0.0)
    return shapely.union_all(polys.polygons)


def _buildings(g: RoadGeometry, p: MeshParams) -> SceneMesh:
    """Boxes on a lot grid inside every block fully enclosed by roads; seeded heights.

    Each block (area enclosed by roads, not touching the network's outer frame) is shrunk
    by the setback and cut on its own ``building_lot`` grid; lots shrink by half the gap.
    """
    roads = _road_footprint(g)
    xmin, ymin, _, xmax, ymax, _ = g.bounds()
    frame = box(xmin - 1, ymin - 1, xmax + 1, ymax + 1)
    blocks = shapely.get_parts(shapely.difference(frame, roads))
    blocks = blocks[~shapely.intersects(blocks, frame.exterior)]
    inner = shapely.buffer(blocks, -p.building_setback, join_style="mitre")
    inner = inner[~shapely.is_empty(inner)]
    if not len(inner):
        return SceneMesh.concatenate([])
    b = shapely.bounds(inner)
    nx = np.ceil((b[:, 2] - b[:, 0]) / p.building_lot).astype(np.int64)
    ny = np.ceil((b[:, 3] - b[:, 1]) / p.building_lot).astype(np.int64)
    per_block = nx * ny
    owner = np.repeat(np.arange(len(inner)), per_block)
    k = np.arange(per_block.sum()) - np.repeat(np.cumsum(per_block) - per_block, per_block)
    x0 = b[owner, 0] + (k % nx[owner]) * p.building_lot
    y0 = b[owner, 1] + (k // nx[owner]) * p.building_lot
    cells = shapely.box(x0, y0, x0 + p.building_lot, y0 + p.building_lot)
    lots = shapely.buffer(
        shapely.intersection(cells, inner[owner]), -p.building_gap / 2, join_style="mitre"
    )
    polys = PolygonSet.from_polygons(lots, np.arange(len(lots)), min_area=p.building_min_area)
    if not len(polys):
        return SceneMesh.concatenate([])
    road_pts = np.concatenate([np.concatenate([ln.left, ln.right]) for ln in g.lanes.values()])
    centroids = shapely.get_coordinates(shapely.centroid(polys.polygons))
    _, nearest = cKDTree(road_pts[:, :2]).query(centroids)
    base = road_pts[nearest, 2]
    rng = np.random.default_rng(p.seed)
    height = rng.uniform(p.building_height_min, p.building_height_max, len(polys))
    z0 = base[polys.vertex_owner]
    return polygon_prism(polys, z0, z0 + height[polys.vertex_owner], Material.BUILDING)


def _ground_height(road_pts: np.ndarray, at: np.ndarray, k: int = 256) -> np.ndarray:
    """(N,) the ground's height at the points ``at`` (N, 2): of the ``k`` road points nearest
    to each, the height nearest to 0 m, so that a building beside a bridge or above a
    tunnel (an OSM import's roads off the ground) stands on the street beside it."""
    _, idx = cKDTree(road_pts[:, :2]).query(at, k=min(k, len(road_pts)))
    z = road_pts[np.asarray(idx).reshape(len(at), -1), 2]
    return z[np.arange(len(at)), np.argmin(np.abs(z), axis=1)]


def _mapped_buildings(g: RoadGeometry, mapped: Sequence[Building]) -> SceneMesh:
    """Each building's footprint extruded to its height from the ground beside it (of the
    road heights nearby, the one nearest to 0 m)."""
    if not mapped:
        return SceneMesh.concatenate([])
    outlines = [np.column_stack([b.outline, np.zeros(len(b.outline))]) for b in mapped]
    polys = PolygonSet.from_outlines(outlines)
    if not len(polys):
        return SceneMesh.concatenate([])
    road_pts = np.concatenate([np.concatenate([ln.left, ln.right]) for ln in g.lanes.values()])
    centroids = shapely.get_coordinates(shapely.centroid(polys.polygons))
    base = _ground_height(road_pts, centroids)
    height = np.array([b.height for b in mapped])[polys.source]
    z0 = base[polys.vertex_owner]
    return polygon_prism(polys, z0, z0 + height[polys.vertex_owner], Material.BUILDING)


def _ground(g: RoadGeometry, p: MeshParams) -> SceneMesh:
    xmin, ymin, zmin, xmax, ymax, _ = g.bounds()
    m, z = p.ground_margin, zmin - p.ground_drop
    v = np.array(
        [
            [xmin - m, ymin - m, z],
            [xmax + m, ymin - m, z],
            [xmax + m, ymax + m, z],
            [xmin - m, ymax + m, z],
        ]
    )
    faces = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)
    return SceneMesh(v, faces, np.full(2, int(Material.GRASS), dtype=np.uint8))


def _drop_degenerate(mesh: SceneMesh, min_area: float = 1e-6) -> SceneMesh:
    """Remove faces with repeated vertices or less than ``min_area`` square metres."""
    t = mesh.triangles
    area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
    f = mesh.faces
    ok = (area >= min_area) & (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    if ok.all():
        return mesh
    return SceneMesh(mesh.vertices, f[ok], mesh.material[ok])
