"""The 3D road scene: Embree ray casts against lane heights, closed solids, paint, exports."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
import trimesh
from embreex import rtcore_scene as rtcs
from embreex.mesh_construction import TriangleMesh
from paths import SHARED
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from shapely.geometry import Point

from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import DISPLAY_RGB, Material
from hiyari.net.mesh.road_mesh import MeshParams, build_scene_mesh, export_mesh
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.net.road.geometry import LaneKind, RoadGeometry
from hiyari.net.sumo.build import (
    CityGridParams,
    ExpresswayParams,
    IntersectionParams,
    R157RoadParams,
    build_city_grid,
    build_expressway,
    build_intersection,
    build_r157_road,
)
from hiyari.net.sumo.opendrive import import_opendrive

ALKS = SHARED / "data" / "opendrive" / "alks"

HILLY_EXPRESSWAY = ExpresswayParams(
    lanes=3, gradient=0.03, curve_left=False, curve_radius=380.0, superelevation=0.08
)


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    """name -> (RoadGeometry, SceneMesh) for each generator and an ALKS road."""
    tmp = tmp_path_factory.mktemp("mesh")
    nets = {
        "expressway": build_expressway(tmp / "ex.net.xml"),
        "hilly": build_expressway(tmp / "hilly.net.xml", HILLY_EXPRESSWAY),
        "city": build_city_grid(tmp / "city.net.xml", CityGridParams(blocks_x=2, blocks_y=2)),
        "intersection": build_intersection(tmp / "x.net.xml", IntersectionParams()),
        "r157": build_r157_road(tmp / "r157.net.xml", R157RoadParams(guard_rails=True)),
        "alks": import_opendrive(
            ALKS / "alks_road_different_curvatures.xodr", tmp / "alks.net.xml"
        ),
    }
    out = {}
    for name, net in nets.items():
        g = RoadGeometry.from_net(net)
        out[name] = (g, build_scene_mesh(g, buildings=name == "city"))
    return out


def _cast(mesh: SceneMesh, origins: np.ndarray, directions: np.ndarray):
    """Embree ray casts: (hit mask, distance m, material id (255: none)) per ray."""
    scene = rtcs.EmbreeScene()
    TriangleMesh(scene, mesh.vertices.astype(np.float32)[mesh.faces])
    res = scene.run(origins.astype(np.float32), directions.astype(np.float32), output=1)
    hit = res["primID"] >= 0
    material = np.where(hit, mesh.material[np.maximum(res["primID"], 0)], 255)
    return hit, res["tfar"].astype(np.float64), material


def _interior_points(lanes) -> np.ndarray:
    """Centre-line vertices and segment midpoints, without the two ends of each lane
    (they lie on the boundary shared with the junction next to them)."""
    pts = []
    for ln in lanes:
        c = ln.centre
        pts += [c[1:-1], 0.5 * (c[1:] + c[:-1])]
    return np.concatenate(pts)


def _face_adjacency(faces: np.ndarray, n_vertices: int):
    """Sparse (F, F) matrix: faces sharing a vertex index are connected."""
    rows = np.repeat(np.arange(len(faces)), 3)
    incidence = coo_matrix(
        (np.ones(faces.size), (rows, faces.ravel())), shape=(len(faces), n_vertices)
    ).tocsr()
    return incidence @ incidence.T


ALL = ["expressway", "hilly", "city", "intersection", "r157", "alks"]


@pytest.mark.parametrize("name", ALL)
def test_downward_rays_hit_road_at_lane_height(scenes, name):
    g, mesh = scenes[name]
    lanes = g.lanes_of(LaneKind.DRIVING, internal=True)
    pts = _interior_points(lanes)
    origins = pts + [0.0, 0.0, 5.0]
    hit, dist, material = _cast(mesh, origins, np.tile([0.0, 0.0, -1.0], (len(pts), 1)))
    assert hit.all()
    assert np.isin(material, [Material.ASPHALT, Material.LANE_PAINT]).all()
    assert np.abs(origins[:, 2] - dist - pts[:, 2]).max() <= 0.02


def test_sidewalks_stand_a_kerb_above_the_road(scenes):
    g, mesh = scenes["city"]
    pts = _interior_points(g.sidewalks)
    origins = pts + [0.0, 0.0, 5.0]
    hit, dist, material = _cast(mesh, origins, np.tile([0.0, 0.0, -1.0], (len(pts), 1)))
    assert hit.all() and (material == Material.CONCRETE).all()
    np.testing.assert_allclose(
        origins[:, 2] - dist, pts[:, 2] + MeshParams().kerb_height, atol=1e-3
    )


def test_guard_rail_beside_the_shoulder(scenes):
    g, mesh = scenes["expressway"]
    p, m = ExpresswayParams(), MeshParams()
    lane = g.lanes["east_in_0"]  # straight: station 0..~410 m, heading +x
    x = np.linspace(20.0, 380.0, 10)
    y = np.interp(x, lane.centre[:, 0], lane.centre[:, 1])
    z = np.interp(x, lane.centre[:, 0], lane.centre[:, 2]) + 0.5 * (
        m.barrier_bottom + m.barrier_top
    )
    origins = np.column_stack([x, y, z])
    hit, dist, material = _cast(mesh, origins, np.tile([0.0, -1.0, 0.0], (len(x), 1)))
    assert hit.all() and (material == Material.BARRIER_METAL).all()
    expected = p.lane_width / 2 + p.shoulder_right + m.barrier_offset - m.barrier_thickness / 2
    np.testing.assert_allclose(dist, expected, atol=0.01)


@pytest.mark.parametrize("name", ALL)
def test_no_degenerate_triangles_and_surfaces_face_up(scenes, name):
    _, mesh = scenes[name]
    t = mesh.triangles
    cross = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    f = mesh.faces
    assert (area > 1e-6).all()
    assert ((f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])).all()
    sheets = np.isin(mesh.material, [Material.ASPHALT, Material.LANE_PAINT, Material.GRASS])
    assert (cross[sheets, 2] > 0).all()


@pytest.mark.parametrize("name", ["expressway", "city", "intersection", "r157"])
def test_solids_are_watertight_with_outward_faces(scenes, name):
    _, mesh = scenes[name]
    solid = np.isin(mesh.material, [Material.CONCRETE, Material.BARRIER_METAL, Material.BUILDING])
    assert solid.any()
    faces = mesh.faces[solid]
    _, label = connected_components(_face_adjacency(faces, len(mesh.vertices)), directed=False)
    assert label.max() >= 1
    for body in range(label.max() + 1):
        tm = trimesh.Trimesh(mesh.vertices, faces[label == body], process=False)
        assert tm.is_watertight and tm.is_winding_consistent
        assert tm.volume > 0  # outward normals


def test_dashed_and_solid_paint_area_on_the_r157_road(scenes):
    g, mesh = scenes["r157"]
    m = MeshParams()
    t = mesh.triangles[mesh.material == Material.LANE_PAINT]
    area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()
    length = 3000.0
    dashes = np.ceil(length / (m.dash_length_fast + m.dash_gap_fast))  # 130 km/h: long dashes
    expected = 2 * length * m.marking_width + dashes * m.dash_length_fast * m.marking_width
    assert area == pytest.approx(expected, rel=1e-6)


def test_zebra_crossings(scenes):
    g, mesh = scenes["intersection"]
    m = MeshParams()
    centre = mesh.triangles.mean(axis=1)
    for crossing in g.crossings:
        inside = shapely.contains_xy(crossing.polygon.buffer(0.01), centre[:, 0], centre[:, 1])
        t = mesh.triangles[inside & (mesh.material == Material.LANE_PAINT)]
        area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()
        period = m.zebra_stripe + m.zebra_gap
        bars = np.ceil(crossing.length / period)
        last = min(m.zebra_stripe, crossing.length - (bars - 1) * period)
        expected = ((bars - 1) * m.zebra_stripe + last) * crossing.width
        assert area == pytest.approx(expected, rel=1e-3)


def test_buildings_stand_on_blocks_not_on_roads(scenes):
    g, mesh = scenes["city"]
    buildings = mesh.faces[mesh.material == Material.BUILDING]
    assert len(buildings) > 100
    feet = mesh.vertices[np.unique(buildings)]
    roads = shapely.union_all([ln.polygon for ln in g.lanes.values()])
    roads = shapely.union_all([roads, *[j.polygon for j in g.junctions.values()]])
    assert not any(roads.contains(Point(x, y)) for x, y in feet[:, :2])
    heights = feet[:, 2].max() - feet[:, 2].min()
    assert MeshParams().building_height_min <= heights <= MeshParams().building_height_max + 0.1


def test_same_net_same_mesh(scenes):
    g, mesh = scenes["city"]
    again = build_scene_mesh(g, buildings=True)
    np.testing.assert_array_equal(mesh.vertices, again.vertices)
    np.testing.assert_array_equal(mesh.faces, again.faces)
    np.testing.assert_array_equal(mesh.material, again.material)


def test_exports_read_back(scenes, tmp_path):
    _, mesh = scenes["intersection"]
    npz = SceneMesh.load_npz(export_mesh(mesh, tmp_path / "scene.npz"))
    np.testing.assert_array_equal(npz.vertices, mesh.vertices)
    np.testing.assert_array_equal(npz.faces, mesh.faces)
    np.testing.assert_array_equal(npz.material, mesh.material)

    ply = trimesh.load(export_mesh(mesh, tmp_path / "scene.ply"), process=False)
    assert len(ply.faces) == len(mesh.faces)
    np.testing.assert_allclose(ply.vertices, mesh.vertices, atol=1e-4)
    expected = np.array([DISPLAY_RGB[Material(int(k))] for k in mesh.material])
    np.testing.assert_array_equal(ply.visual.face_colors[:, :3], expected)

    for suffix in (".glb", ".gltf"):
        scene = trimesh.load(export_mesh(mesh, tmp_path / f"scene{suffix}"), process=False)
        parts = scene.geometry
        assert set(parts) == {Material(int(k)).name.lower() for k in np.unique(mesh.material)}
        assert sum(len(p.faces) for p in parts.values()) == len(mesh.faces)
        asphalt = parts["asphalt"]
        np.testing.assert_allclose(
            asphalt.visual.material.baseColorFactor[:3], DISPLAY_RGB[Material.ASPHALT]
        )
        # glTF is y-up: the network's z becomes y, its y becomes -z
        y_up = np.concatenate([p.vertices for p in parts.values()])
        assert y_up[:, 1].min() == pytest.approx(mesh.vertices[:, 2].min(), abs=1e-4)
        assert -y_up[:, 2].max() == pytest.approx(mesh.vertices[:, 1].min(), abs=1e-3)


def test_unknown_export_format(scenes, tmp_path):
    _, mesh = scenes["r157"]
    with pytest.raises(HiyariError, match="unknown mesh format"):
        export_mesh(mesh, tmp_path / "scene.obj")
    assert list(tmp_path.iterdir()) == []
