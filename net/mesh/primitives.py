"""Triangle primitives of the road scene, built for many items at once with numpy.

- strips: a sheet between two borders (road surface, paint), facing up;
- border prisms: a closed solid between two borders from a bottom to a top height (kerbs,
  sidewalks, guard rails);
- polygon sheets and polygon prisms (junction areas, walking areas, buildings), triangulated
  with shapely's constrained Delaunay triangulation so that only ring vertices are used.

Every face is counter-clockwise seen from outside (from above for sheets). Coordinates are
SUMO network metres, z up.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.spatial import cKDTree

from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.net.road.polylines import Polylines

#: Separates polygons in the vertex look-up tree (larger than any map extent, in metres).
_OWNER_STRIDE = 1.0e7


def _mesh(vertices: np.ndarray, faces: np.ndarray, material: Material) -> SceneMesh:
    faces = np.asarray(faces, dtype=np.int32).reshape(-1, 3)
    return SceneMesh(
        np.asarray(vertices, dtype=np.float64).reshape(-1, 3),
        faces,
        np.full(len(faces), int(material), dtype=np.uint8),
    )


def strip(left: np.ndarray, right: np.ndarray, lines: Polylines, material: Material) -> SceneMesh:
    """Sheet between ``left`` and ``right`` borders (P, 3) of the packed ``lines``, facing up."""
    n = len(left)
    i = np.flatnonzero(lines.segment_mask)
    j = i + 1
    r_i, r_j, l_i, l_j = n + i, n + j, i, j
    faces = np.concatenate([np.stack([r_i, r_j, l_j], 1), np.stack([r_i, l_j, l_i], 1)])
    vertices = np.concatenate([left, right])
    # Where a border folds over itself (the inner side of a very tight bend) the quad turns
    # over; keep every face looking up.
    t = vertices[faces]
    nz = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 2]
    faces[nz < 0] = faces[nz < 0][:, ::-1]
    return _mesh(vertices, faces, material)


def border_prism(
    left: np.ndarray,
    right: np.ndarray,
    lines: Polylines,
    bottom: float,
    top: float,
    material: Material,
) -> SceneMesh:
    """Closed solid between ``left``/``right`` base borders, from base z + bottom to + top."""
    n = len(left)
    base = np.stack([left, right, right, left], 1)  # per point: LB, RB, RT, LT
    base[:, :2, 2] += bottom
    base[:, 2:, 2] += top
    vertices = base.reshape(-1, 3)
    lb, rb, rt, lt = (4 * np.arange(n) + k for k in range(4))
    i = np.flatnonzero(lines.segment_mask)
    j = i + 1
    faces = [
        (rt[i], rt[j], lt[j]),
        (rt[i], lt[j], lt[i]),
        (rb[i], lb[j], rb[j]),
        (rb[i], lb[i], lb[j]),
        (rb[i], rb[j], rt[j]),
        (rb[i], rt[j], rt[i]),
        (lb[i], lt[j], lb[j]),
        (lb[i], lt[i], lt[j]),
    ]
    a = np.flatnonzero(lines.is_first)
    b = np.flatnonzero(lines.is_last)
    faces += [
        (lb[a], rb[a], rt[a]),
        (lb[a], rt[a], lt[a]),
        (lb[b], rt[b], rb[b]),
        (lb[b], lt[b], rt[b]),
    ]
    return _mesh(vertices, np.concatenate([np.stack(f, 1) for f in faces]), material)


@dataclass(frozen=True, eq=False)
class PolygonSet:
    """Valid plan-view polygons with a height per ring vertex, ready to triangulate.

    ``rings`` holds every ring's vertices (no closing repeat); ``ring_offsets`` delimits the
    rings, ``ring_owner`` gives each ring's polygon and ``ring_is_hole`` marks holes. Exterior
    rings run counter-clockwise, holes clockwise.
    """

    polygons: np.ndarray  # (K,) shapely Polygons (2D)
    rings: np.ndarray  # (R, 3)
    ring_offsets: np.ndarray  # (nrings + 1,)
    ring_owner: np.ndarray  # (nrings,)
    source: np.ndarray  # (K,) index of the input outline each polygon came from

    @staticmethod
    def from_outlines(
        outlines: Sequence[np.ndarray],
        min_area: float = 0.05,
        tolerance: float = 1e-3,
        grow: float = 0.0,
    ) -> PolygonSet:
        """Polygons from (n, 3) outlines; invalid ones are repaired, tiny ones dropped.

        ``grow`` > 0 widens every outline by that many metres (mitred), including outlines
        that enclose no area (a junction drawn as a line at a dead end), which become thin
        strips. Repair (self-intersections), growing and simplification (``tolerance``
        metres, removes collinear and repeated points) may add or move vertices: their
        height is the height of the nearest original vertex of the same outline.
        """
        counts = np.array([len(o) for o in outlines], dtype=np.int64)
        used = np.flatnonzero(counts >= (2 if grow > 0 else 3))
        geoms = np.full(len(used), None, dtype=object)
        areal = counts[used] >= 3
        if areal.any():
            geoms[areal] = shapely.polygons(_ragged(shapely.linearrings, outlines, used[areal]))
            bad = areal & ~shapely.is_valid(geoms)
            geoms[bad] = shapely.make_valid(geoms[bad])
        if grow > 0:
            thin = ~areal | (shapely.area(geoms) < min_area)
            if thin.any():
                geoms[thin] = _ragged(shapely.linestrings, outlines, used[thin])
            geoms = shapely.buffer(
                geoms, grow, cap_style="square", join_style="mitre", mitre_limit=2.0
            )
        geoms = shapely.simplify(geoms, tolerance)
        return PolygonSet.from_polygons(geoms, used, outlines, min_area)

    @staticmethod
    def from_polygons(
        geoms: np.ndarray,
        source: np.ndarray,
        outlines: Sequence[np.ndarray] | None = None,
        min_area: float = 0.05,
    ) -> PolygonSet:
        """From shapely geometries (their polygon parts of at least ``min_area`` m^2).

        ``source`` gives each geometry's index into ``outlines``, whose nearest vertex gives
        each ring vertex its height; without outlines every height is 0.
        """
        parts, which = shapely.get_parts(np.asarray(geoms, dtype=object), return_index=True)
        ok = (shapely.get_type_id(parts) == 3) & (shapely.area(parts) >= min_area)
        ok &= shapely.is_valid(parts)
        polys = shapely.orient_polygons(parts[ok], exterior_cw=False)
        src = np.asarray(source, dtype=np.int64)[which[ok]]
        rings, ring_owner = shapely.get_rings(polys, return_index=True)
        coords, coord_ring = shapely.get_coordinates(rings, return_index=True)
        per_ring = np.bincount(coord_ring, minlength=len(rings))
        keep = np.ones(len(coords), dtype=bool)
        keep[np.cumsum(per_ring) - 1] = False  # the closing repeat of each ring
        flat = coords[keep]
        counts = per_ring - 1
        offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        if outlines is None:
            z = np.zeros(len(flat))
        else:
            z = _heights_from_outlines(flat, src[np.repeat(ring_owner, counts)], outlines)
        return PolygonSet(polys, np.column_stack([flat, z]), offsets, ring_owner, src)

    def __len__(self) -> int:
        return len(self.polygons)

    @property
    def vertex_owner(self) -> np.ndarray:
        """(R,) polygon index of each ring vertex."""
        return np.repeat(self.ring_owner, np.diff(self.ring_offsets))

    def triangles(self) -> np.ndarray:
        """(T, 3) indices into ``rings``: triangles covering every polygon, CCW from above."""
        if len(self) == 0:
            return np.zeros((0, 3), dtype=np.int64)
        tri = shapely.constrained_delaunay_triangles(self.polygons)
        parts, owner = shapely.get_parts(tri, return_index=True)
        coords = shapely.get_coordinates(parts).reshape(-1, 4, 2)[:, :3]
        keys = np.column_stack([self.rings[:, :2], self.vertex_owner * _OWNER_STRIDE])
        query = np.column_stack([coords.reshape(-1, 2), np.repeat(owner, 3) * _OWNER_STRIDE])
        dist, idx = cKDTree(keys).query(query)
        if np.any(dist > 1e-6):
            raise RuntimeError("triangulation produced a vertex that is not on a ring")
        faces = idx.reshape(-1, 3)
        p = self.rings[faces, :2]
        cross = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (
            p[:, 1, 1] - p[:, 0, 1]
        ) * (p[:, 2, 0] - p[:, 0, 0])
        faces[cross < 0] = faces[cross < 0][:, ::-1]
        return faces[np.abs(cross) > 1e-9]


def _ragged(
    make: Callable[..., np.ndarray], outlines: Sequence[np.ndarray], which: np.ndarray
) -> np.ndarray:
    """Vectorised shapely construction (linearrings / linestrings) of several outlines."""
    xy = np.concatenate([outlines[k][:, :2] for k in which])
    index = np.repeat(np.arange(len(which)), [len(outlines[k]) for k in which])
    return make(xy, indices=index)


def _heights_from_outlines(
    xy: np.ndarray, source: np.ndarray, outlines: Sequence[np.ndarray]
) -> np.ndarray:
    if len(xy) == 0:
        return np.zeros(0)
    used = np.unique(source)
    pts = np.concatenate([outlines[k] for k in used])
    owner = np.concatenate([np.full(len(outlines[k]), k) for k in used])
    tree = cKDTree(np.column_stack([pts[:, :2], owner * _OWNER_STRIDE]))
    _, idx = tree.query(np.column_stack([xy, source * _OWNER_STRIDE]))
    return pts[idx, 2]


def polygon_sheet(polys: PolygonSet, lift: float, material: Material) -> SceneMesh:
    """Upward-facing triangulated polygons at ring height + ``lift`` metres."""
    vertices = polys.rings.copy()
    vertices[:, 2] += lift
    return _mesh(vertices, polys.triangles(), material)


def polygon_prism(
    polys: PolygonSet, bottom: np.ndarray, top: np.ndarray, material: Material
) -> SceneMesh:
    """Closed extruded polygons: each ring vertex from z ``bottom`` to ``top`` ((R,) each)."""
    n = len(polys.rings)
    top_v = np.column_stack([polys.rings[:, :2], top])
    bot_v = np.column_stack([polys.rings[:, :2], bottom])
    tri = polys.triangles()
    a = np.arange(n)
    nxt = a + 1
    ends = polys.ring_offsets[1:] - 1
    nxt[ends] = polys.ring_offsets[:-1]
    walls = np.concatenate([np.stack([a + n, nxt + n, nxt], 1), np.stack([a + n, nxt, a], 1)])
    faces = np.concatenate([tri, tri[:, ::-1] + n, walls])
    return _mesh(np.concatenate([top_v, bot_v]), faces, material)
