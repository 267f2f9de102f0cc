"""The fast LiDAR recogniser finds exactly what the straightforward one finds.

The reference below is the recogniser before it was optimised (full-grid labelling, here of the
graph of cells within reach of each other, ufunc.at per object); both run on real scans of the built-in street, clear and in
heavy rain (drop ghosts), from several ego positions. The recogniser now reports each object
at the centre of its fitted oriented box (tests/unit/sensors/test_lidar_box_fit.py); the same objects are
checked here through the clusters' axis-aligned boxes, which the reference reported.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage, sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.recognition import (
    LidarRecognitionConfig,
    _class_from_size,
    _ground_reference,
    find_clusters,
    recognise_lidar,
)
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.outputs import PointCloud
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, street_scenario


def reference(cloud: PointCloud, cfg: LidarRecognitionConfig) -> dict[str, np.ndarray]:
    """Objects as the straightforward recogniser finds them (arrays of the kept objects)."""
    rot, t = cloud.sensor_to_world[:3, :3], cloud.sensor_to_world[:3, 3]
    x, y, z = (cloud.xyz[:, k] for k in range(3))
    wx = rot[0, 0] * x + rot[0, 1] * y + rot[0, 2] * z
    wy = rot[1, 0] * x + rot[1, 1] * y + rot[1, 2] * z
    wz = rot[2, 0] * x + rot[2, 1] * y + rot[2, 2] * z + t[2]
    h = cfg.roi_half_size_m
    idx = np.flatnonzero((np.abs(wx) < h) & (np.abs(wy) < h))
    wx, wy, wz = wx[idx], wy[idx], wz[idx].astype(np.float32)
    ng = int(np.ceil(2 * h / cfg.ground_cell_m))
    gi = ((wx + h) / cfg.ground_cell_m).astype(np.int64).clip(0, ng - 1)
    gj = ((wy + h) / cfg.ground_cell_m).astype(np.int64).clip(0, ng - 1)
    zmin = np.full(ng * ng, np.inf, np.float32)
    np.minimum.at(zmin, gi * ng + gj, wz)
    zmin = ndimage.minimum_filter(zmin.reshape(ng, ng), size=3, mode="nearest").ravel()
    above = wz - _ground_reference(zmin, ng, h, cfg)[gi * ng + gj]
    obj = (above > cfg.ground_tolerance_m) & (above < cfg.max_height_m)
    idx, wx, wy, above = idx[obj], wx[obj], wy[obj], above[obj]
    nc = int(np.ceil(2 * h / cfg.cluster_cell_m))
    ci = ((wx + h) / cfg.cluster_cell_m).astype(np.int64).clip(0, nc - 1)
    cj = ((wy + h) / cfg.cluster_cell_m).astype(np.int64).clip(0, nc - 1)
    occ = np.bincount(ci * nc + cj, minlength=nc * nc).reshape(nc, nc) >= cfg.min_cell_points
    solid = occ[ci, cj]
    idx, ci, cj, above = idx[solid], ci[solid], cj[solid], above[solid]
    # cells up to `reach` apart, centre to centre, connect: components of that graph
    cells = np.argwhere(occ)
    pairs = cKDTree(cells).query_pairs(cfg.cluster_reach_cells, output_type="ndarray")
    graph = sparse.coo_matrix(
        (np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(cells), len(cells))
    )
    count, comp = csgraph.connected_components(graph, directed=False)
    cell_label = np.full((nc, nc), -1, np.int64)
    cell_label[cells[:, 0], cells[:, 1]] = comp
    lab = cell_label[ci, cj]
    # numbered in raster order of each object's first cell one row and column up-left (the
    # order ndimage gives a 3 x 3 dilation)
    first = np.full(count, np.iinfo(np.int64).max)
    np.minimum.at(first, lab, np.maximum(ci - 1, 0) * nc + np.maximum(cj - 1, 0))
    rank = np.empty(count, np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(count)
    lab = rank[lab]
    n_pts = np.bincount(lab, minlength=count)
    lo = np.full((count, 3), np.inf, np.float32)
    hi = np.full((count, 3), -np.inf, np.float32)
    for k in range(3):
        np.minimum.at(lo[:, k], lab, cloud.xyz[idx, k])
        np.maximum.at(hi[:, k], lab, cloud.xyz[idx, k])
    top = np.full(count, -np.inf, np.float32)
    np.maximum.at(top, lab, above)
    lo, hi = lo.astype(np.float64), hi.astype(np.float64)
    ext = hi - lo
    length, width = np.maximum(ext[:, 0], ext[:, 1]), np.minimum(ext[:, 0], ext[:, 1])
    keep = (n_pts >= cfg.min_points) & (top >= cfg.min_height_m) & (length <= cfg.max_extent_m)
    codes = len(cloud.actor_ids) + 2
    hit = cloud.hit[idx].astype(np.int64)
    votes = np.bincount(lab * codes + hit + 2, minlength=count * codes).reshape(count, codes)
    best = votes.argmax(1) - 2
    truth = np.array(
        [cloud.actor_ids[b] if b >= 0 else ("static" if b == -1 else "") for b in best], object
    )
    return {
        "position": ((lo + hi) / 2)[keep],
        "size": np.stack([length, width, top], 1)[keep],
        "cls": _class_from_size(length[keep], width[keep], top[keep]),
        "truth": truth[keep],
        "confidence": np.clip(n_pts[keep] / (4.0 * cfg.min_points), 0.0, 1.0),
    }


@pytest.mark.parametrize("rain", [0.0, 80.0])
def test_fast_recogniser_equals_reference_on_street_scans(rain: float) -> None:
    world = street_scenario(occluder=True)
    scene = RayScene(StraightRoad().mesh())
    lidar = Lidar(LidarConfig.preset("64ch"), Mount(x=0.0, z=1.9))
    cfg = LidarRecognitionConfig()
    found = 0
    for k, x in enumerate((0.0, 40.0, 120.0)):
        world.xyz[0, 0] = x
        scene.update(world, "ego")
        cloud = lidar.scan(
            scene,
            world.pose_of("ego"),
            world,
            Environment(rain_mm_h=rain),
            np.random.default_rng(k),
        )
        fast = recognise_lidar(cloud, cfg)
        ref = reference(cloud, cfg)
        assert len(fast) == len(ref["truth"])
        cl = find_clusters(cloud, cfg)
        ext = cl.hi - cl.lo
        length = np.maximum(ext[:, 0], ext[:, 1])
        kept = (cl.n_points >= cfg.min_points) & (cl.top >= cfg.min_height_m)
        kept &= length <= cfg.max_extent_m
        boxes = {
            "position": ((cl.lo + cl.hi) / 2)[kept],
            "size": np.stack([length, np.minimum(ext[:, 0], ext[:, 1]), cl.top], 1)[kept],
        }
        for name, values in ref.items():
            got = boxes[name] if name in boxes else getattr(fast, name)
            assert np.array_equal(got, values), name
        found += int(np.sum(fast.truth != "static"))
    assert found >= 6  # actors are among the objects, not only walls


def test_cells_join_within_reach_centre_to_centre() -> None:
    """Cells two rows and one or two columns apart (2.2 and 2.8 cells) are two objects at the
    default reach of 2 cells; two rows apart in one column (2 cells) are one. Joined row and
    column apart each, a truck beside the ego and a car ahead in its lane, 0.5 m apart
    lengthwise and 1.2 m sideways, made one box over the ego's lane (blind-spot set, #30)."""
    from hiyari.sensors.lidar.clustering import label_cells

    nc = 10

    def objects(*cells: tuple[int, int]) -> int:
        bev = np.array([r * nc + c for r, c in cells for _ in range(3)], np.int64)
        counts = np.bincount(bev, minlength=nc * nc).astype(np.int64)
        return label_cells(bev, counts, 2, nc, LidarRecognitionConfig().cluster_reach_cells)[1]

    assert objects((4, 4), (6, 4)) == 1
    assert objects((4, 4), (4, 6)) == 1
    assert objects((4, 4), (6, 5)) == 2
    assert objects((4, 4), (6, 6)) == 2
    assert objects((4, 4), (5, 5), (6, 6)) == 1  # a diagonal line of cells stays one object
