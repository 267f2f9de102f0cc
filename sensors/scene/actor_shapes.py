"""One low-polygon shape per actor class, placed for every actor of a WorldState in one go.

Templates are unit boxes scaled by each actor's length, width and height: x along the heading
in [-0.5, 0.5], y to the left in [-0.5, 0.5], z up in [0, 1]. Each face carries a Part that an
ActorAppearance turns into a Material (paint, glass, licence plates, clothing, skin). Faces of
bodies that are round in reality (people, riders, helmets) are flagged ``rounded``: sensors
shade them with the normal of the ellipsoid inscribed in their box, so a dark glossy jacket
glints only in a small spot as a real one does (divp-H section 3.4, the black-leather dummy).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np

from hiyari.kinematics import vehicle_to_world
from hiyari.net.mesh.materials import Material
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState


class Part(IntEnum):
    """What a template face is, before an appearance picks its material."""

    PAINT = 0
    GLASS = 1
    PLATE = 2
    CLOTHING = 3
    SKIN = 4


@dataclass(frozen=True)
class ActorAppearance:
    """Materials of actors: clothing for everyone, and per-actor clothing overrides."""

    clothing: Material = Material.CLOTHING
    """Clothing of every pedestrian and rider (DARK_CLOTHING: the seed's black leather)."""
    clothing_by_id: Mapping[str, Material] = field(default_factory=dict)
    """Clothing of particular actors by SUMO id, overriding ``clothing``."""

    def part_materials(self) -> np.ndarray:
        """(len(Part),) uint8 material per part for actors without an override."""
        table = np.zeros(len(Part), np.uint8)
        table[Part.PAINT] = Material.VEHICLE_PAINT
        table[Part.GLASS] = Material.VEHICLE_GLASS
        table[Part.PLATE] = Material.RETROREFLECTOR
        table[Part.CLOTHING] = self.clothing
        table[Part.SKIN] = Material.SKIN
        return table


@dataclass(frozen=True, eq=False)
class Template:
    """A unit shape: vertices (V, 3), faces (F, 3), part and rounded flag per face."""

    vertices: np.ndarray
    faces: np.ndarray
    part: np.ndarray
    rounded: np.ndarray
    centre: np.ndarray  # (F, 3) centre of the face's box, unit coordinates
    half: np.ndarray  # (F, 3) half-size of the face's box, unit coordinates


def _box(
    lo: Sequence[float],
    hi: Sequence[float],
    part: Part,
    sides: Part | None = None,
    rounded: bool = False,
    bottom: bool = False,
) -> tuple[np.ndarray, ...]:
    """Box between corners ``lo`` and ``hi``; ``sides`` overrides the part of the 4 side walls."""
    v = np.array(
        [
            [(lo[0], hi[0])[i >> 2 & 1], (lo[1], hi[1])[i >> 1 & 1], (lo[2], hi[2])[i & 1]]
            for i in range(8)
        ],
        float,
    )
    quads = {  # vertex index = 4 ix + 2 iy + iz
        "x0": (0, 1, 3, 2),
        "x1": (4, 6, 7, 5),
        "y0": (0, 4, 5, 1),
        "y1": (2, 3, 7, 6),
        "z1": (1, 5, 7, 3),
        "z0": (0, 2, 6, 4),
    }
    faces, parts, rnd = [], [], []
    centre = v.mean(0)
    half = (v.max(0) - v.min(0)) / 2
    for name, (a, b, c, d) in quads.items():
        if name == "z0" and not bottom:
            continue
        side = name[0] in "xy"
        for tri in ((a, b, c), (a, c, d)):
            p = v[list(tri)]
            n = np.cross(p[1] - p[0], p[2] - p[0])
            if n @ (p.mean(0) - centre) < 0:  # wind counter-clockwise seen from outside
                tri = (tri[0], tri[2], tri[1])
            faces.append(tri)
            parts.append(sides if (side and sides is not None) else part)
            rnd.append(rounded and side)
    nf = len(faces)
    return (
        v,
        np.array(faces),
        np.array(parts, np.uint8),
        np.array(rnd, bool),
        np.tile(centre, (nf, 1)),
        np.tile(half, (nf, 1)),
    )


def _join(*boxes) -> Template:
    vs, fs, off = [], [], 0
    for b in boxes:
        vs.append(b[0])
        fs.append(b[1] + off)
        off += len(b[0])
    cat = [np.concatenate([b[k] for b in boxes]) for k in range(2, 6)]
    return Template(np.concatenate(vs), np.concatenate(fs).astype(np.int32), *cat)


_PLATE_Z = (0.22, 0.32)
_EPS = 0.004  # plates stand proud of the body so they win the ray cast


def _plate(x: float, outward: float):
    """A licence plate: one quad just proud of the end face at ``x``, facing ``outward`` (+-1)."""
    z0, z1 = _PLATE_Z
    xp = x + outward * _EPS
    v = np.array([[xp, -0.13, z0], [xp, 0.13, z0], [xp, 0.13, z1], [xp, -0.13, z1]])
    f = np.array([[0, 1, 2], [0, 2, 3]]) if outward > 0 else np.array([[0, 2, 1], [0, 3, 2]])
    centre, half = v.mean(0), np.array([_EPS, 0.13, (z1 - z0) / 2])
    return (
        v,
        f,
        np.full(2, Part.PLATE, np.uint8),
        np.zeros(2, bool),
        np.tile(centre, (2, 1)),
        np.tile(half, (2, 1)),
    )


def _plates(front: bool = True):
    return [_plate(-0.5, -1.0)] + ([_plate(0.5, 1.0)] if front else [])


TEMPLATES: dict[ActorClass, Template] = {
    ActorClass.CAR: _join(
        _box((-0.5, -0.5, 0.12), (0.5, 0.5, 0.55), Part.PAINT),
        _box((-0.32, -0.44, 0.55), (0.22, 0.44, 1.0), Part.PAINT, sides=Part.GLASS, bottom=False),
        *_plates(),
    ),
    ActorClass.TRUCK: _join(
        _box((-0.5, -0.5, 0.12), (0.27, 0.5, 1.0), Part.PAINT),
        _box((0.29, -0.5, 0.1), (0.5, 0.5, 0.5), Part.PAINT),
        _box((0.29, -0.48, 0.5), (0.5, 0.48, 0.8), Part.PAINT, sides=Part.GLASS, bottom=False),
        *_plates(),
    ),
    ActorClass.BUS: _join(
        _box((-0.5, -0.5, 0.1), (0.5, 0.5, 0.45), Part.PAINT),
        _box((-0.5, -0.5, 0.45), (0.5, 0.5, 0.88), Part.GLASS, bottom=False),
        _box((-0.5, -0.5, 0.88), (0.5, 0.5, 1.0), Part.PAINT, bottom=False),
        *_plates(),
    ),
    ActorClass.MOTORCYCLE: _join(
        _box((-0.5, -0.25, 0.12), (0.5, 0.25, 0.5), Part.PAINT),
        _box((-0.3, -0.45, 0.5), (0.1, 0.45, 0.86), Part.CLOTHING, rounded=True),
        _box((-0.2, -0.22, 0.86), (0.02, 0.22, 1.0), Part.PAINT, rounded=True),
        *_plates(front=False),
    ),
    ActorClass.BICYCLE: _join(
        _box((-0.5, -0.12, 0.1), (0.5, 0.12, 0.55), Part.PAINT),
        _box((-0.25, -0.4, 0.35), (0.1, 0.4, 0.86), Part.CLOTHING, rounded=True),
        _box((-0.15, -0.22, 0.88), (0.02, 0.22, 1.0), Part.SKIN, rounded=True),
    ),
    ActorClass.PEDESTRIAN: _join(
        _box((-0.4, -0.35, 0.0), (0.4, 0.35, 0.47), Part.CLOTHING, rounded=True),
        _box((-0.5, -0.5, 0.47), (0.5, 0.5, 0.86), Part.CLOTHING, rounded=True),
        _box((-0.45, -0.28, 0.87), (0.45, 0.28, 1.0), Part.SKIN, rounded=True),
    ),
}


@dataclass(frozen=True, eq=False)
class ActorMesh:
    """Triangles of all actors of one WorldState, in network coordinates."""

    vertices: np.ndarray  # (V, 3) float32
    faces: np.ndarray  # (F, 3) int32
    material: np.ndarray  # (F,) uint8
    actor_row: np.ndarray  # (F,) int32: row of the face's actor in the WorldState
    rounded: np.ndarray  # (F,) bool
    #: (F, 3) centre and half-size of each face's part box, unit template coordinates
    unit_boxes: tuple[np.ndarray, np.ndarray]
    world: WorldState  # the state the actors were placed from

    def __len__(self) -> int:
        return len(self.faces)

    def part_boxes(self, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Of the part boxes of ``faces`` (indices): the centre (K, 3) in network
        coordinates, the half-size (K, 3) along heading, left and up (m) and the actor's
        heading (K,) (rad), all float32. Placed only for the faces asked for (the rays' hits
        on rounded faces), with the arithmetic per element of placing them all."""
        w, r = self.world, self.actor_row[faces]
        size = np.stack([w.length[r], w.width[r], w.height[r]], 1)
        centre, half = self.unit_boxes
        placed = vehicle_to_world(centre[faces] * size, w.xyz[r], w.heading[r])
        return (
            placed.astype(np.float32),
            (half[faces] * size).astype(np.float32),
            w.heading[r].astype(np.float32),
        )


@dataclass(frozen=True, eq=False)
class _Layout:
    """Which template vertex and face belongs to which actor: all of a mesh but the poses."""

    vertex_row: np.ndarray  # (V,) WorldState row of each vertex's actor
    local: np.ndarray  # (V, 3) template vertex, unit coordinates
    faces: np.ndarray  # (F, 3) int32
    material: np.ndarray  # (F,) uint8
    actor_row: np.ndarray  # (F,) int32
    rounded: np.ndarray  # (F,) bool
    centre: np.ndarray  # (F, 3) centre of the face's part box, unit coordinates
    half: np.ndarray  # (F, 3) half-size of the face's part box, unit coordinates


def _layout(world: WorldState, appearance: ActorAppearance, keep: np.ndarray) -> _Layout:
    """The layout of the kept actors: class by class in TEMPLATES order, rows ascending."""
    base = appearance.part_materials()
    vrows, local, faces, mats, rows_out, rnd, centres, halves = [], [], [], [], [], [], [], []
    offset = 0
    for cls, tpl in TEMPLATES.items():
        rows = np.flatnonzero(keep & (world.cls == cls))
        if rows.size == 0:
            continue
        nv, nf = len(tpl.vertices), len(tpl.faces)
        vrows.append(np.repeat(rows, nv))
        local.append(np.tile(tpl.vertices, (rows.size, 1)))
        faces.append(
            (tpl.faces[None] + (offset + np.arange(rows.size) * nv)[:, None, None]).reshape(-1, 3)
        )
        m = np.broadcast_to(base[tpl.part], (rows.size, nf)).copy()
        if appearance.clothing_by_id:
            cloth = tpl.part == Part.CLOTHING
            for i, r in enumerate(rows):
                own = appearance.clothing_by_id.get(world.ids[r])
                if own is not None:
                    m[i, cloth] = own
        mats.append(m.ravel())
        rows_out.append(np.repeat(rows, nf))
        rnd.append(np.tile(tpl.rounded, rows.size))
        centres.append(np.tile(tpl.centre, (rows.size, 1)))
        halves.append(np.tile(tpl.half, (rows.size, 1)))
        offset += rows.size * nv
    if not vrows:
        z3 = np.zeros((0, 3))
        return _Layout(
            np.zeros(0, np.int64), z3, np.zeros((0, 3), np.int32), np.zeros(0, np.uint8),
            np.zeros(0, np.int32), np.zeros(0, bool), z3, z3,
        )  # fmt: skip
    return _Layout(
        np.concatenate(vrows),
        np.concatenate(local),
        np.concatenate(faces).astype(np.int32),
        np.concatenate(mats).astype(np.uint8),
        np.concatenate(rows_out).astype(np.int32),
        np.concatenate(rnd),
        np.concatenate(centres),
        np.concatenate(halves),
    )


def _place(layout: _Layout, world: WorldState) -> ActorMesh:
    """The layout's templates scaled to each actor's size and placed at its pose (the same
    arithmetic per element as placing each class's actors in one array); the part boxes are
    placed only when asked for (:meth:`ActorMesh.part_boxes`)."""
    size = np.stack([world.length, world.width, world.height], 1)
    v = layout.vertex_row
    verts = vehicle_to_world(layout.local * size[v], world.xyz[v], world.heading[v])
    return ActorMesh(
        verts.astype(np.float32),
        layout.faces,
        layout.material,
        layout.actor_row,
        layout.rounded,
        (layout.centre, layout.half),
        world,
    )


def build_actor_mesh(
    world: WorldState, appearance: ActorAppearance, exclude: np.ndarray | None = None
) -> ActorMesh:
    """Place every actor's template at its pose; ``exclude`` (bool per row) drops actors."""
    keep = np.ones(len(world), bool) if exclude is None else ~exclude
    return _place(_layout(world, appearance, keep), world)


class ActorMeshBuilder:
    """:func:`build_actor_mesh` step after step, keeping the last layout: when the kept actors'
    classes (and, with per-actor clothing, their ids) are those of the last call, only the
    poses are placed anew, and the triangles are the same as the last mesh's."""

    def __init__(self) -> None:
        self._key: tuple | None = None
        self._appearance: ActorAppearance | None = None
        self._layout: _Layout | None = None

    def build(
        self, world: WorldState, appearance: ActorAppearance, exclude: np.ndarray | None = None
    ) -> tuple[ActorMesh, bool]:
        """The mesh, and whether its triangles are the last call's (only vertices moved)."""
        keep = np.ones(len(world), bool) if exclude is None else ~exclude
        ids = tuple(world.ids[keep]) if appearance.clothing_by_id else ()
        key = (keep.tobytes(), world.cls.tobytes(), ids)
        same = self._layout is not None and key == self._key and appearance is self._appearance
        if not same:
            self._layout, self._key = _layout(world, appearance, keep), key
            self._appearance = appearance
        return _place(self._layout, world), same
