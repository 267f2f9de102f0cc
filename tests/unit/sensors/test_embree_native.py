"""Embree called from compiled code (sensors/scene/embree_native.py) against embreex, and the
actor meshes placed step after step (ActorMeshBuilder) against placing them class by class."""

from __future__ import annotations

import numpy as np
import pytest
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

from hiyari.kinematics import vehicle_to_world
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.scene.actor_shapes import (
    TEMPLATES,
    ActorAppearance,
    ActorMeshBuilder,
    build_actor_mesh,
)
from hiyari.sensors.scene.embree_native import Device, TriangleScene
from hiyari.sensors.scene.synthetic import StraightRoad, street_scenario


def _street() -> tuple[np.ndarray, np.ndarray]:
    """The built-in street with its actors: vertices (float32), faces (int32)."""
    world = street_scenario(occluder=True)
    actors = build_actor_mesh(world, ActorAppearance(), world.ids == "ego")
    both = SceneMesh.concatenate(
        [
            StraightRoad().mesh(),
            SceneMesh(actors.vertices.astype(np.float64), actors.faces, actors.material),
        ]
    )
    return both.vertices.astype(np.float32), both.faces.astype(np.int32)


def _rays(n: int, seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d[:, 2] = -np.abs(d[:, 2]) * 0.3  # mostly towards the road and the actors
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.tile(np.array([0.0, -1.75, 1.9], np.float32), (n, 1))
    return o, d.astype(np.float32)


def test_native_hits_are_embreex_hits_bit_for_bit():
    v, f = _street()
    o, d = _rays(4001)  # not a multiple of 8: the last packet is partly masked
    ref = rtcore_scene.EmbreeScene()
    TriangleMesh(ref, v, f)
    tfar = np.full(len(d), 80.0, np.float32)
    tfar[::7] = 12.0  # per-ray limits
    r = ref.run(o, d, dists=tfar, output=1)
    scene = TriangleScene(Device(), v, f)
    for packets in (True, False):
        prim, t, ng = scene.intersect(o, d, tfar, packets)
        assert (prim >= 0).sum() > 1000 and (prim < 0).sum() > 100
        np.testing.assert_array_equal(prim, r["primID"])
        np.testing.assert_array_equal(t, r["tfar"])
        hit = prim >= 0
        np.testing.assert_array_equal(ng[hit], r["Ng"][hit])
    # one limit for every ray
    prim, t, _ = scene.intersect(o, d, 80.0)
    np.testing.assert_array_equal(prim, ref.run(o, d, dists=np.float32(80.0), output=1)["primID"])


def test_a_refitted_scene_answers_as_a_rebuilt_one():
    world = street_scenario()
    keep = world.ids != "ego"
    mesh = build_actor_mesh(world, ActorAppearance(), ~keep)
    device = Device()
    scene = TriangleScene(device, mesh.vertices, mesh.faces, refit=True)
    # rays from the ego's roof towards the actors, spread over a few metres
    rng = np.random.default_rng(5)
    target = np.repeat(world.xyz[keep], 400, 0) + rng.normal(0.0, 1.5, (400 * keep.sum(), 3))
    o = np.tile(np.array([0.0, -1.75, 1.9]), (len(target), 1)).astype(np.float32)
    d = target + [0.0, 0.0, 1.0] - o
    d = (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
    for step in range(1, 4):  # the actors drive on 1.5 m per step
        world.xyz[keep, 0] += 1.5 * np.cos(world.heading[keep])
        world.xyz[keep, 1] += 1.5 * np.sin(world.heading[keep])
        moved = build_actor_mesh(world, ActorAppearance(), ~keep)
        scene.move(moved.vertices)
        fresh = TriangleScene(device, moved.vertices, moved.faces)
        got, want = scene.intersect(o, d, 60.0), fresh.intersect(o, d, 60.0)
        assert (got[0] >= 0).sum() > 300, step
        for a, b in zip(got, want, strict=True):
            np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="vertex count"):
        scene.move(moved.vertices[:-1])


def _reference(world, keep):
    """Each class's actors placed in one array (the placement before the builder)."""
    size = np.stack([world.length, world.width, world.height], 1)
    verts, centres = [], []
    for cls, tpl in TEMPLATES.items():
        rows = np.flatnonzero(keep & (world.cls == cls))
        if rows.size:
            origin, heading = world.xyz[rows, None, :], world.heading[rows, None]
            p = tpl.vertices[None] * size[rows, None, :]
            verts.append(vehicle_to_world(p, origin, heading).reshape(-1, 3))
            c = tpl.centre[None] * size[rows, None, :]
            centres.append(vehicle_to_world(c, origin, heading).reshape(-1, 3))
    return np.concatenate(verts).astype(np.float32), np.concatenate(centres).astype(np.float32)


def test_actor_mesh_builder_reuses_the_layout_and_places_bit_for_bit():
    world = street_scenario(occluder=True)
    exclude = world.ids == "ego"
    builder = ActorMeshBuilder()
    app = ActorAppearance()
    first, same = builder.build(world, app, exclude)
    assert not same
    world.xyz[:, 0] += np.linspace(0.1, 2.3, len(world))
    world.heading[:] += 0.01
    moved, same = builder.build(world, app, exclude)
    assert same
    np.testing.assert_array_equal(moved.faces, first.faces)
    verts, centres = _reference(world, ~exclude)
    np.testing.assert_array_equal(moved.vertices, verts)
    every = np.arange(len(moved))
    np.testing.assert_array_equal(moved.part_boxes(every)[0], centres)
    # the part boxes of a few faces are those faces' rows of all of them
    some = every[::7]
    for got, want in zip(moved.part_boxes(some), moved.part_boxes(every), strict=True):
        np.testing.assert_array_equal(got, want[some])
    fresh = build_actor_mesh(world, app, exclude)
    for name in ("material", "actor_row", "rounded"):
        np.testing.assert_array_equal(getattr(moved, name), getattr(fresh, name))
    for got, want in zip(moved.part_boxes(every), fresh.part_boxes(every), strict=True):
        np.testing.assert_array_equal(got, want)
    # another actor left out, or other clothing: a new layout
    _, same = builder.build(world, app, exclude | (world.ids == world.ids[-1]))
    assert not same
    _, same = builder.build(world, ActorAppearance(), exclude)
    assert not same
