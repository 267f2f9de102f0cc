"""Small hand-built scenes and actor sets for tests, examples and the CLI's built-in scenario.

These are deliberately simple (flat quads and boxes with materials); real networks come from
hiyari.net (road_mesh.build_scene_mesh). Coordinates in metres, z up.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState


def quad(corners: Sequence[Sequence[float]], material: Material) -> SceneMesh:
    """Two triangles over four corners given counter-clockwise seen from the front side."""
    v = np.asarray(corners, dtype=np.float64).reshape(4, 3)
    return SceneMesh(v, np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.full(2, material, np.uint8))


def box(lo: Sequence[float], hi: Sequence[float], material: Material) -> SceneMesh:
    """Closed axis-aligned box between corners ``lo`` and ``hi``, faces wound outward."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    parts = [
        quad([(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)], material),
        quad([(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)], material),
        quad([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)], material),
        quad([(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)], material),
        quad([(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)], material),
        quad([(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)], material),
    ]
    return SceneMesh.concatenate(parts)


def wall(x: float, y0: float, y1: float, height: float, material: Material) -> SceneMesh:
    """A vertical wall in the plane x = const facing -x, from y0 to y1, 0..height m."""
    return quad([(x, y0, 0), (x, y0, height), (x, y1, height), (x, y1, 0)], material)


@dataclass(frozen=True)
class StraightRoad:
    """A straight road along +x from x0 to x1: lanes, markings, kerbs, sidewalks, buildings."""

    x0: float = -60.0
    x1: float = 260.0
    lanes: int = 2
    lane_width: float = 3.5
    sidewalk_width: float = 3.0
    kerb_height: float = 0.15
    dash_length: float = 5.0
    dash_gap: float = 5.0
    line_width: float = 0.15
    buildings: bool = True
    guard_rail: bool = False

    def mesh(self) -> SceneMesh:
        """The road as a SceneMesh; the centre of the road is y = 0."""
        half = self.lanes * self.lane_width / 2
        x0, x1 = self.x0, self.x1
        parts = [
            quad([(x0, -half, 0), (x1, -half, 0), (x1, half, 0), (x0, half, 0)], Material.ASPHALT)
        ]
        lift = 0.005  # markings sit just above the asphalt so they win the ray cast
        w = self.line_width / 2
        for y in (-half + 0.3, half - 0.3):
            parts.append(
                quad(
                    [(x0, y - w, lift), (x1, y - w, lift), (x1, y + w, lift), (x0, y + w, lift)],
                    Material.LANE_PAINT,
                )
            )
        for k in range(1, self.lanes):
            y = -half + k * self.lane_width
            xs = np.arange(x0, x1, self.dash_length + self.dash_gap)
            for a in xs:
                b = min(a + self.dash_length, x1)
                parts.append(
                    quad(
                        [(a, y - w, lift), (b, y - w, lift), (b, y + w, lift), (a, y + w, lift)],
                        Material.LANE_PAINT,
                    )
                )
        s = self.sidewalk_width
        kh = self.kerb_height
        parts.append(box((x0, half, 0), (x1, half + s, kh), Material.CONCRETE))
        parts.append(box((x0, -half - s, 0), (x1, -half, kh), Material.CONCRETE))
        outer = half + s
        parts.append(
            quad(
                [(x0, outer, 0), (x1, outer, 0), (x1, outer + 40, 0), (x0, outer + 40, 0)],
                Material.GRASS,
            )
        )
        parts.append(
            quad(
                [(x0, -outer - 40, 0), (x1, -outer - 40, 0), (x1, -outer, 0), (x0, -outer, 0)],
                Material.GRASS,
            )
        )
        if self.guard_rail:
            for y in (half + 0.5, -half - 0.5):
                parts.append(box((x0, y - 0.05, 0.5), (x1, y + 0.05, 0.8), Material.BARRIER_METAL))
        if self.buildings:
            for x in np.arange(x0, x1, 30.0):
                for y in (outer + 4, -outer - 16):
                    parts.append(box((x, y, 0), (x + 22, y + 12, 12.0), Material.BUILDING))
        return SceneMesh.concatenate(parts)


def actor_world(
    actors: Sequence[dict],
    time: float = 0.0,
) -> WorldState:
    """A WorldState from dicts with keys id, cls (ActorClass), x, y and optionally z, heading,
    speed, length, width, height (defaults: the class's size, ActorClass.size, at rest, heading 0)."""
    n = len(actors)
    cls = np.array([int(a["cls"]) for a in actors], np.int8)
    size = np.array([ActorClass(c).size.as_tuple() for c in cls]).reshape(n, 3)
    xyz = np.array([[a["x"], a["y"], a.get("z", 0.0)] for a in actors], np.float64).reshape(n, 3)
    return WorldState(
        time=time,
        ids=np.array([a["id"] for a in actors], dtype=object),
        cls=cls,
        xyz=xyz,
        heading=np.array([a.get("heading", 0.0) for a in actors], np.float64),
        speed=np.array([a.get("speed", 0.0) for a in actors], np.float64),
        accel=np.zeros(n),
        length=np.array([a.get("length", size[i, 0]) for i, a in enumerate(actors)], np.float64),
        width=np.array([a.get("width", size[i, 1]) for i, a in enumerate(actors)], np.float64),
        height=np.array([a.get("height", size[i, 2]) for i, a in enumerate(actors)], np.float64),
        lane=np.full(n, "", dtype=object),
        edge=np.full(n, "", dtype=object),
    )


def street_scenario(occluder: bool = False, ego_speed: float = 8.0) -> WorldState:
    """The built-in street: ego in the right lane of StraightRoad at x = 0 heading +x, a lead
    car 35 m ahead, a pedestrian crossing 22 m ahead, a cyclist on the right, an oncoming car
    and bus in the left lane; ``occluder`` parks a truck that half hides the pedestrian."""
    lane = -1.75
    actors = [
        dict(id="ego", cls=ActorClass.CAR, x=0.0, y=lane, speed=ego_speed),
        dict(id="lead", cls=ActorClass.CAR, x=35.0, y=lane, speed=6.0),
        dict(
            id="pedestrian",
            cls=ActorClass.PEDESTRIAN,
            x=22.0,
            y=lane - 0.5,
            heading=np.pi / 2,
            speed=1.3,
        ),
        dict(id="cyclist", cls=ActorClass.BICYCLE, x=14.0, y=-3.0, speed=4.0),
        dict(id="oncoming", cls=ActorClass.CAR, x=60.0, y=-lane, heading=np.pi, speed=10.0),
        dict(id="bus", cls=ActorClass.BUS, x=95.0, y=-lane, heading=np.pi, speed=9.0),
    ]
    if occluder:
        actors.append(dict(id="parked_truck", cls=ActorClass.TRUCK, x=15.0, y=lane - 0.5 + 1.2))
    return actor_world(actors)
