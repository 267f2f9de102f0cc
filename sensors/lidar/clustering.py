"""Compiled passes of the LiDAR recogniser: ground grid, bird's-eye clustering, per-cluster sums.

Each pass is one loop over the points (or the occupied cells) in numba, so a 120 k-point scan
costs a few array passes instead of numpy's dozens of temporaries. The arithmetic is the
one the straightforward numpy recogniser does, in the same order and precision (float64
rotation, float32 heights and thresholds), so the objects are the same bit for bit.

Frames: ``xyz`` is the sensor frame; "offsets" are the points minus the sensor position along
the network axes (x east, y north, z up), in metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.jit import njit


@njit(cache=True)
def _offset(xyz: np.ndarray, p: int, rot: np.ndarray, row: int) -> float:
    """Row ``row`` of rot @ xyz[p] in float64, summed in numpy's order."""
    x, y, z = np.float64(xyz[p, 0]), np.float64(xyz[p, 1]), np.float64(xyz[p, 2])
    return rot[row, 0] * x + rot[row, 1] * y + rot[row, 2] * z


@njit(cache=True)
def ground_pass(
    xyz: np.ndarray, rot: np.ndarray, tz: float, half: float, cells: tuple[float, int, float, int]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Points inside the square region of half side ``half`` (m) around the sensor.

    ``cells`` = (ground cell m, ground cells per side, bird's-eye cell m, bird's-eye cells
    per side). Returns the points' rows in ``xyz``, network height z (float32, m), ground
    cell and bird's-eye cell (raster indices), and the lowest z per ground cell (inf where
    empty).
    """
    g_m, ng, c_m, nc = cells
    n = xyz.shape[0]
    idx = np.empty(n, np.int32)
    wz = np.empty(n, np.float32)
    cell = np.empty(n, np.int32)
    bev = np.empty(n, np.int32)
    zmin = np.full(ng * ng, np.inf, np.float32)
    m = 0
    for p in range(n):
        a = _offset(xyz, p, rot, 0)
        b = _offset(xyz, p, rot, 1)
        if not (abs(a) < half and abs(b) < half):
            continue
        c = np.float32(_offset(xyz, p, rot, 2) + tz)
        k = min(int((a + half) / g_m), ng - 1) * ng + min(int((b + half) / g_m), ng - 1)
        idx[m], wz[m], cell[m] = p, c, k
        bev[m] = min(int((a + half) / c_m), nc - 1) * nc + min(int((b + half) / c_m), nc - 1)
        if c < zmin[k]:
            zmin[k] = c
        m += 1
    return idx[:m], wz[:m], cell[:m], bev[:m], zmin


@njit(cache=True)
def min_filter_3x3(grid: np.ndarray) -> np.ndarray:
    """Minimum over each cell's 3 x 3 neighbourhood, edges repeated (ndimage mode 'nearest')."""
    ni, nj = grid.shape
    out = np.empty_like(grid)
    for i in range(ni):
        for j in range(nj):
            v = grid[i, j]
            for a in range(max(i - 1, 0), min(i + 2, ni)):
                for b in range(max(j - 1, 0), min(j + 2, nj)):
                    if grid[a, b] < v:
                        v = grid[a, b]
            out[i, j] = v
    return out


@njit(cache=True)
def object_cells(
    wz: np.ndarray,
    cell: np.ndarray,
    bev: np.ndarray,
    ground: np.ndarray,
    low: np.float32,
    high: np.float32,
    n_bev: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points between ``low`` and ``high`` above their cell's ground (float32 comparisons, m).

    Returns their positions in the ground-pass arrays, their height above ground (float32,
    m), and the point count of each of the ``n_bev`` bird's-eye cells.
    """
    n = len(wz)
    sel = np.empty(n, np.int32)
    above = np.empty(n, np.float32)
    counts = np.zeros(n_bev, np.int32)
    m = 0
    for p in range(n):
        h = wz[p] - ground[cell[p]]
        if h > low and h < high:
            sel[m], above[m] = p, h
            counts[bev[p]] += 1
            m += 1
    return sel[:m], above[:m], counts


@njit(cache=True)
def _root(parent: np.ndarray, a: int) -> int:
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@njit(cache=True)
def label_cells(
    bev: np.ndarray, counts: np.ndarray, min_count: int, nc: int, reach: int
) -> tuple[np.ndarray, int]:
    """Connected objects of the occupied bird's-eye cells; label per point (-1: cell dropped).

    A cell is occupied with ``min_count`` points or more; two occupied cells belong to one
    object when they are at most ``reach`` cells apart, centre to centre (row and column
    differences dr, dc with dr^2 + dc^2 <= reach^2; reach 1: 4-connectivity). Labels are numbered like ndimage.label numbers the dilated grid:
    in raster order of each object's first dilated cell. ``counts`` is overwritten.
    """
    # occupied cells get ids -1, -2, ... in the grid itself (no second nc x nc array)
    occ = np.empty(len(bev), np.int64)
    n_occ = 0
    for p in range(len(bev)):
        k = bev[p]
        if counts[k] >= min_count:
            counts[k] = -(n_occ + 1)
            occ[n_occ] = k
            n_occ += 1
    occ = occ[:n_occ]
    parent = np.arange(n_occ)
    for a in range(n_occ):
        r, c = occ[a] // nc, occ[a] % nc
        # each pair is met from one side: rows above, and the left part of the own row
        for i in range(max(r - reach, 0), r + 1):
            for j in range(max(c - reach, 0), min(c + reach + 1, nc) if i < r else c):
                v = counts[i * nc + j]
                if v < 0 and (i - r) ** 2 + (j - c) ** 2 <= reach * reach:
                    ra, rb = _root(parent, a), _root(parent, -v - 1)
                    if ra != rb:
                        parent[max(ra, rb)] = min(ra, rb)
    first = np.full(n_occ, np.iinfo(np.int64).max)
    for a in range(n_occ):
        r, c = occ[a] // nc, occ[a] % nc
        key = max(r - 1, 0) * nc + max(c - 1, 0)
        ra = _root(parent, a)
        if key < first[ra]:
            first[ra] = key
    roots = np.flatnonzero(first != np.iinfo(np.int64).max)
    order = roots[np.argsort(first[roots], kind="mergesort")]
    comp = np.full(n_occ, -1, np.int64)
    comp[order] = np.arange(len(order))
    lab = np.full(len(bev), -1, np.int64)
    for p in range(len(bev)):
        v = counts[bev[p]]
        if v < 0:
            lab[p] = comp[_root(parent, -v - 1)]
    return lab, len(order)


@dataclass(frozen=True)
class Clusters:
    """Objects of one scan before filtering: per-object sums, and their points grouped.

    Point arrays index the object points (``point``: row in the PointCloud); ``members``
    lists them object by object, object k's in ``members[start[k]:start[k + 1]]``.
    """

    n_points: np.ndarray  # (K,) points per object
    lo: np.ndarray  # (K, 3) float64 low corner of the sensor-frame points, m
    hi: np.ndarray  # (K, 3) float64 high corner, m
    top: np.ndarray  # (K,) float32 greatest height above ground, m
    start: np.ndarray  # (K + 1,) offsets into members
    members: np.ndarray  # (P,) object points grouped by object, in scan order within each
    point: np.ndarray  # (P,) PointCloud row of each object point
    offset_xy: np.ndarray  # (P, 2) float64 x/y offsets from the sensor, network axes, m
    # (only the rows listed in members are set)


@njit(cache=True)
def cluster_sums(
    xyz: np.ndarray,
    point: np.ndarray,
    above: np.ndarray,
    lab: np.ndarray,
    count: int,
    rot: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per label 0..count-1: point count, float32 low/high corners of the sensor-frame
    points ``xyz[point]``, greatest ``above``; a stable grouping (offsets, member list) of the
    points with label >= 0; and each such point's x/y offset from the sensor along the network
    axes (``rot`` = sensor-to-network rotation), m."""
    n_pts = np.zeros(count, np.int64)
    lo = np.full((count, 3), np.inf, np.float32)
    hi = np.full((count, 3), -np.inf, np.float32)
    top = np.full(count, -np.inf, np.float32)
    offset = np.empty((len(lab), 2))
    for p in range(len(lab)):
        k = lab[p]
        if k < 0:
            continue
        n_pts[k] += 1
        row = point[p]
        offset[p, 0] = _offset(xyz, row, rot, 0)
        offset[p, 1] = _offset(xyz, row, rot, 1)
        for d in range(3):
            v = xyz[row, d]
            if v < lo[k, d]:
                lo[k, d] = v
            if v > hi[k, d]:
                hi[k, d] = v
        if above[p] > top[k]:
            top[k] = above[p]
    start = np.zeros(count + 1, np.int64)
    start[1:] = np.cumsum(n_pts)
    fill = start[:-1].copy()
    members = np.empty(start[-1], np.int64)
    for p in range(len(lab)):
        k = lab[p]
        if k >= 0:
            members[fill[k]] = p
            fill[k] += 1
    return n_pts, lo, hi, top, start, members, offset


@njit(cache=True)
def majority_code(
    codes: np.ndarray, members: np.ndarray, start: np.ndarray, objects: np.ndarray, n_codes: int
) -> np.ndarray:
    """Most frequent code in 0..n_codes-1 among each listed object's members (the smallest
    code on ties, as argmax)."""
    tally = np.zeros(n_codes, np.int64)
    best = np.empty(len(objects), np.int64)
    for o in range(len(objects)):
        k = objects[o]
        for q in range(start[k], start[k + 1]):
            tally[codes[members[q]]] += 1
        b = 0
        for q in range(start[k], start[k + 1]):
            c = codes[members[q]]
            if tally[c] > tally[b] or (tally[c] == tally[b] and c < b):
                b = c
        best[o] = b
        for q in range(start[k], start[k + 1]):
            tally[codes[members[q]]] = 0
    return best
