"""The ray-cast scene: the static road mesh (built into Embree once) plus the actors of a step.

Updating the actors never rebuilds the static part: the static triangles live in one Embree
scene committed at construction, the actors in a small second scene that ``update`` refits
when the actors' triangles are the same as before (the same classes in the same order: only
their positions changed) and rebuilds otherwise. Queries are Embree packets of 8 rays from
compiled code (sensors/scene/embree_native.py; benchmarks/ray_engines.py has the choice).
``cast`` shoots every ray into the static scene, then only the rays whose azimuth can reach an
actor's bounding sphere into the actor scene, limited to the static hit distance, and keeps
the nearer hit. Frames: network coordinates (metres); directions unit vectors.
"""

from __future__ import annotations

import weakref
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from hiyari.errors import HiyariError
from hiyari.kinematics import rotate_xy, unrotate_xy
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.outputs import HIT_NONE
from hiyari.sensors.scene.actor_shapes import (
    ActorAppearance,
    ActorMesh,
    ActorMeshBuilder,
    build_actor_mesh,
)
from hiyari.sensors.scene.cast_kernel import actor_candidates, static_hits
from hiyari.sensors.scene.embree_native import Device, TriangleScene
from hiyari.traffic.world_state import WorldState

NO_MATERIAL = 255


AZIMUTH_BINS = 1440
"""Azimuth bins (0.25 deg) used to find which rays may reach an actor."""

CAST_CHUNK = 8192
"""Rays per chunk of a parallel static cast (16 chunks per 64 x 2048 scan)."""

REFITS = 30
"""Refits of the actor scene before it is rebuilt anyway (about 1 s of updates at 30 Hz): a
refitted BVH keeps the grouping of its build, which loosens as actors move apart."""


@dataclass(frozen=True, eq=False)
class DirectionIndex:
    """A sensor's fixed ray directions (sensor frame) with their azimuth bin (built once)."""

    directions: np.ndarray  # (N, 3) float32, sensor frame, unit
    bin: np.ndarray  # (N,) int32 azimuth bin of each ray
    elevation: np.ndarray  # (N,) float32 elevation of each ray, rad

    @staticmethod
    def build(directions: np.ndarray) -> DirectionIndex:
        """Index unit ``directions`` (N, 3) given in the sensor frame."""
        d = np.ascontiguousarray(directions, dtype=np.float32)
        az = np.arctan2(d[:, 1], d[:, 0]).astype(np.float64)
        b = np.floor((az + np.pi) / (2 * np.pi) * AZIMUTH_BINS).astype(np.int32) % AZIMUTH_BINS
        el = np.arcsin(np.clip(d[:, 2], -1.0, 1.0)).astype(np.float32)
        return DirectionIndex(d, b, el)

    def __len__(self) -> int:
        return len(self.directions)


@dataclass(frozen=True, eq=False)
class SensorRays:
    """Where a bundle of rays comes from: lets ``cast`` skip rays that cannot reach an actor."""

    index: DirectionIndex
    origin: np.ndarray  # (3,) sensor position, network frame
    rotation: np.ndarray  # (3, 3) sensor-to-network rotation
    pad: float = 0.0  # m added to actor bounding spheres (motion during a scan)


@dataclass(frozen=True, eq=False)
class Hits:
    """Nearest surface per ray. Arrays have one row per ray."""

    distance: np.ndarray  # (N,) float32, m along the ray; inf where nothing was hit
    hit: np.ndarray  # (N,) int32: actor row, HIT_STATIC or HIT_NONE
    material: np.ndarray  # (N,) uint8 Material, NO_MATERIAL where nothing was hit
    cos_incidence: np.ndarray  # (N,) float32 |cos| between ray and shading normal, 0 on a miss
    normal: np.ndarray | None  # (N, 3) float32 unit shading normal facing the ray, or None


class RayScene:
    """Static mesh plus per-step actor shapes, ray-cast with Embree (packets of 8 rays).

    Build once per network: ``scene = RayScene(mesh, workers=2)``; then per step
    ``scene.update(world, ego_id)`` (the ego is left out so that sensors do not see their own
    vehicle), and sensors call ``scene.cast``.
    """

    def __init__(
        self,
        static: SceneMesh,
        appearance: ActorAppearance | None = None,
        actor_radius_m: float = 250.0,
        workers: int = 1,
    ) -> None:
        self.appearance = appearance or ActorAppearance()
        # static casts split over ``workers`` threads: hits are per ray, so the result is the
        # same bit for bit whatever the split
        self._pool = None
        if workers > 1:
            self._pool = ThreadPoolExecutor(workers, thread_name_prefix="hiyari-cast")
            weakref.finalize(self, self._pool.shutdown, wait=False)
        self.actor_radius_m = actor_radius_m
        self._device = Device()
        self.static_mesh = static
        self._static_material_ext = np.append(
            static.material.astype(np.uint8), np.uint8(NO_MATERIAL)
        )
        self._static_normal_ext = np.zeros((len(static.faces) + 1, 3), np.float32)
        if len(static.faces):
            tri = static.triangles
            n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
            self._static_normal_ext[:-1] = n
        self._static = None
        if len(static.faces):
            self._static = self._commit(
                static.vertices.astype(np.float32), static.faces.astype(np.int32)
            )
        self.world: WorldState = WorldState.empty()
        self.ego_id: str | None = None
        self.actors: ActorMesh = build_actor_mesh(self.world, self.appearance)
        self._builder = ActorMeshBuilder()
        self._dynamic: TriangleScene | None = None
        self._refits = 0
        self._centres = np.zeros((0, 3))
        self._radius = np.zeros(0)
        self._velocity: np.ndarray | None = None

    def _commit(
        self, vertices: np.ndarray, faces: np.ndarray, refit: bool = False
    ) -> TriangleScene:
        return TriangleScene(self._device, vertices, faces, refit)

    def _actor_scene(self, actors: ActorMesh, same: bool) -> TriangleScene | None:
        """The actor scene of ``actors``: the last one refitted when the triangles are the
        ``same`` (up to REFITS times in a row), else a new one."""
        if not len(actors):
            return None
        last = self._dynamic
        if last is not None and same and self._refits < REFITS:
            last.move(actors.vertices)
            self._refits += 1
            return last
        self._refits = 0
        return self._commit(actors.vertices, actors.faces, refit=True)

    def set_appearance(self, appearance: ActorAppearance) -> None:
        """Change actor materials (takes effect at the next update)."""
        self.appearance = appearance

    def update(self, world: WorldState, ego_id: str | None = None) -> None:
        """Replace the actors by those of ``world``; static part untouched.

        The ego (``ego_id``) is left out, and so are actors farther than ``actor_radius_m``
        from it, which no sensor reaches.
        """
        exclude = None
        if ego_id is not None:
            is_ego = world.ids == ego_id
            if not is_ego.any():
                raise HiyariError(f"ego {ego_id!r} is not in the WorldState at t={world.time} s")
            far = (
                np.linalg.norm(world.xyz[:, :2] - world.xyz[is_ego][0, :2], axis=1)
                > self.actor_radius_m
            )
            exclude = is_ego | far
        self.world, self.ego_id = world, ego_id
        self.actors, same = self._builder.build(world, self.appearance, exclude)
        self._dynamic = self._actor_scene(self.actors, same)
        keep = np.ones(len(world), bool) if exclude is None else ~exclude
        rows = np.flatnonzero(keep)
        centre = world.xyz[rows].copy()
        centre[:, 2] += world.height[rows] / 2
        self._rows = rows
        self._centres = centre
        self._radius = 0.5 * np.sqrt(
            world.length[rows] ** 2 + world.width[rows] ** 2 + world.height[rows] ** 2
        )
        self._velocity = None  # placed when a sensor asks (actor_velocity)

    def ensure(self, world: WorldState) -> None:
        """Update to ``world`` (keeping the ego id) unless it is already the current one."""
        if world is not self.world:
            ego = self.ego_id if np.any(world.ids == self.ego_id) else None
            self.update(world, ego)

    def actor_velocity(self, rows: np.ndarray) -> np.ndarray:
        """(n, 3) network-frame velocity of actors at WorldState ``rows``, m/s."""
        if self._velocity is None:
            vel = np.zeros((len(self.world), 3))
            vel[:, :2] = self.world.velocity
            self._velocity = vel
        return self._velocity[rows]

    def actor_bins(self, rays: SensorRays, max_range: float) -> tuple[np.ndarray, ...]:
        """Per sensor-frame azimuth bin (AZIMUTH_BINS,): the distance to the nearest actor
        bounding sphere (inf where none), and the lowest and highest elevation (rad) at which
        any of those spheres is seen."""
        near = np.full(AZIMUTH_BINS, np.inf, np.float32)
        low = np.full(AZIMUTH_BINS, np.inf, np.float32)
        high = np.full(AZIMUTH_BINS, -np.inf, np.float32)
        if self._dynamic is None:
            return near, low, high
        rel = (self._centres - rays.origin) @ rays.rotation
        rad = self._radius + rays.pad
        dist = np.linalg.norm(rel, axis=1)
        keep = dist - rad < max_range
        rel, rad, dist = rel[keep], rad[keep], dist[keep]
        if not len(dist):
            return near, low, high
        dh = np.hypot(rel[:, 0], rel[:, 1])
        inside = dist <= rad
        half = np.where(dh > rad, np.arcsin(np.minimum(rad / np.maximum(dh, 1e-9), 1.0)), np.pi)
        az = np.arctan2(rel[:, 1], rel[:, 0])
        el = np.arctan2(rel[:, 2], dh)
        spread = np.where(inside, np.pi, np.arcsin(np.minimum(rad / np.maximum(dist, 1e-9), 1.0)))
        w = 2 * np.pi / AZIMUTH_BINS
        b0 = np.floor((az - half + np.pi) / w).astype(np.int64)
        count = np.minimum(
            np.floor((az + half + np.pi) / w).astype(np.int64) - b0 + 1, AZIMUTH_BINS
        )
        start = np.repeat(np.cumsum(count) - count, count)
        bins = (np.repeat(b0, count) + np.arange(count.sum()) - start) % AZIMUTH_BINS
        np.minimum.at(near, bins, np.repeat(np.maximum(dist - rad, 0.0), count).astype(np.float32))
        np.minimum.at(low, bins, np.repeat(el - spread, count).astype(np.float32))
        np.maximum.at(high, bins, np.repeat(el + spread, count).astype(np.float32))
        return near, low, high

    def _ellipsoid_normal(self, prim: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Normals at ``points`` of the ellipsoids inscribed in the part boxes of faces ``prim``."""
        centre, half, heading = self.actors.part_boxes(prim)
        d = points - centre
        half2 = half**2
        fwd, left = unrotate_xy(d[:, 0], d[:, 1], heading)
        x, y = rotate_xy(fwd / half2[:, 0], left / half2[:, 1], heading)
        return np.stack([x, y, d[:, 2] / half2[:, 2]], 1).astype(np.float32)

    def _cast_static(
        self, origins: np.ndarray, directions: np.ndarray, max_range: float, out: Hits
    ) -> None:
        """Static-scene hits into ``out`` (filled with misses), in chunks spread over the
        worker threads: Embree and the compiled pass over a chunk release the GIL."""
        n = len(directions)

        tables = (self._static_material_ext, self._static_normal_ext)
        no_normal = np.zeros((0, 3), np.float32)

        def chunk(a: int, b: int) -> None:
            d = directions[a:b]
            prim, tfar, _ = self._static.intersect(origins[a:b], d, np.float32(max_range))
            normal = out.normal[a:b] if out.normal is not None else no_normal
            parts = (out.distance[a:b], out.hit[a:b], out.material[a:b], out.cos_incidence[a:b])
            static_hits(prim, tfar, d, tables, (*parts, normal))

        if self._pool is None or n < 2 * CAST_CHUNK:
            chunk(0, n)
            return
        # many chunks, fetched by whichever thread is free: rays into the sky cost less than
        # rays onto the road, and a scan's rows are ordered by elevation
        bounds = range(0, n, CAST_CHUNK)
        for f in [self._pool.submit(chunk, a, min(a + CAST_CHUNK, n)) for a in bounds]:
            f.result()

    def cast(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        max_range: float,
        rays: SensorRays | None = None,
        normals: bool = False,
        actors: bool = True,
    ) -> Hits:
        """Nearest hit per ray within ``max_range`` m.

        ``origins`` and ``directions`` are (N, 3) float32 in network coordinates (directions
        unit). With ``rays`` (the sensor's index and pose) only rays that pass an actor's
        azimuth and reach beyond its nearest distance before hitting the static scene are cast
        into the actor scene; without it every ray is. ``actors=False`` casts against the
        static scene only. ``normals`` also returns unit shading normals.
        """
        n = len(directions)
        out = Hits(
            np.full(n, np.inf, np.float32),
            np.full(n, HIT_NONE, np.int32),
            np.full(n, NO_MATERIAL, np.uint8),
            np.zeros(n, np.float32),
            np.zeros((n, 3), np.float32) if normals else None,
        )
        if self._static is not None:
            self._cast_static(origins, directions, max_range, out)
        if actors and self._dynamic is not None:
            self._cast_actors(origins, directions, max_range, rays, out)
        return out

    def _cast_actors(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        max_range: float,
        rays: SensorRays | None,
        out: Hits,
    ) -> None:
        """Cast the rays that may reach an actor into the actor scene; nearer hits replace
        the static ones in ``out``."""
        if rays is None:
            idx = np.arange(len(directions))
        else:
            bins = self.actor_bins(rays, max_range)
            idx = actor_candidates(out.distance, rays.index.bin, rays.index.elevation, bins)
        if not len(idx):
            return
        limit = np.minimum(out.distance[idx], np.float32(max_range))
        prim_all, tfar, ng_all = self._dynamic.intersect(origins[idx], directions[idx], limit)
        dh = prim_all >= 0
        j = idx[dh]
        prim = prim_all[dh]
        out.distance[j] = tfar[dh]
        out.hit[j] = self.actors.actor_row[prim]
        out.material[j] = self.actors.material[prim]
        ng = ng_all[dh]
        rnd = self.actors.rounded[prim]
        if rnd.any():
            ng[rnd] = self._ellipsoid_normal(
                prim[rnd], origins[j[rnd]] + directions[j[rnd]] * out.distance[j[rnd], None]
            )
        nrm = ng / np.maximum(np.linalg.norm(ng, axis=1, keepdims=True), np.float32(1e-9))
        d = directions[j]
        dot = nrm[:, 0] * d[:, 0] + nrm[:, 1] * d[:, 1] + nrm[:, 2] * d[:, 2]
        out.cos_incidence[j] = np.abs(dot)
        if out.normal is not None:
            out.normal[j] = nrm * np.where(dot > 0, np.float32(-1), np.float32(1))[:, None]
