"""Oriented boxes for LiDAR clusters: L-shape fit, then completion to the class's size prior.

The heading search is Zhang et al. (2017), "Efficient L-Shape Fitting for Vehicle Detection
Using Laser Scanners", with their closeness criterion: for each candidate heading the points
are projected on the two box axes, and each point scores 1 / max(d, d0), d its distance to the
nearer of the two box edges of its nearer axis; the heading with the highest score wins. A
coarse sweep of [0, 90) degrees is refined around the best step.

Before the search the bird's-eye points are merged on a fine grid (one mean point per cell):
a vertical face gives a column of returns per azimuth that project to one spot, so merging
keeps the outline, weights it evenly along its length (near parts are not over-counted) and
cuts the points by an order of magnitude.

All geometry here is 2D, in the horizontal plane: x/y offsets from the sensor along the
network axes (m), headings counter-clockwise from the network x axis (rad).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.jit import njit


@dataclass(frozen=True)
class BoxFitConfig:
    """Parameters of the L-shape fit and the size-prior completion (toolkit choices)."""

    merge_cell_m: float = 0.1
    """Bird's-eye cell in which points are merged to their mean before the search, m."""
    closeness_floor_m: float = 0.05
    """d0 of the closeness criterion: nearer points all score 1 / d0 (about 2x the range
    noise, so noise does not decide the heading), m."""
    coarse_step_deg: float = 3.0
    """Heading step of the first sweep over [0, 90) degrees."""
    fine_step_deg: float = 0.25
    """Heading step of the refinement within one coarse step either side of the best."""
    length_margin_m: float = 0.5
    """A visible extent longer than the class's prior width by this much is the length; a
    shorter box is ambiguous (an end face, or a short piece of a side), m."""


@njit(cache=True)
def _merge(px: np.ndarray, py: np.ndarray, cell_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Mean point of each occupied ``cell_m`` grid cell, cells in raster order."""
    x0, y0 = px.min(), py.min()
    nx = int((px.max() - x0) / cell_m) + 1
    ny = int((py.max() - y0) / cell_m) + 1
    sx = np.zeros(nx * ny)
    sy = np.zeros(nx * ny)
    cnt = np.zeros(nx * ny, np.int64)
    for p in range(len(px)):
        k = int((px[p] - x0) / cell_m) * ny + int((py[p] - y0) / cell_m)
        sx[k] += px[p]
        sy[k] += py[p]
        cnt[k] += 1
    used = np.flatnonzero(cnt)
    return sx[used] / cnt[used], sy[used] / cnt[used]


@njit(cache=True)
def _closeness(x: np.ndarray, y: np.ndarray, theta: float, d0: float) -> float:
    """Zhang et al.'s closeness score of heading ``theta`` (rad) for points x, y (m)."""
    c, s = np.cos(theta), np.sin(theta)
    lo1 = lo2 = np.inf
    hi1 = hi2 = -np.inf
    for p in range(len(x)):
        a = c * x[p] + s * y[p]
        b = -s * x[p] + c * y[p]
        lo1, hi1 = min(lo1, a), max(hi1, a)
        lo2, hi2 = min(lo2, b), max(hi2, b)
    score = 0.0
    for p in range(len(x)):
        a = c * x[p] + s * y[p]
        b = -s * x[p] + c * y[p]
        d = min(min(hi1 - a, a - lo1), min(hi2 - b, b - lo2))
        score += 1.0 / max(d, d0)
    return score


@njit(cache=True)
def _best_heading(x: np.ndarray, y: np.ndarray, cfg: tuple[float, float, float]) -> float:
    """Heading in [0, pi/2) maximising the closeness score (first of equals), rad."""
    d0, coarse, fine = cfg
    best, best_score = 0.0, -1.0
    n_coarse = int(np.ceil(0.5 * np.pi / coarse - 1e-9))
    for k in range(n_coarse):
        sc = _closeness(x, y, k * coarse, d0)
        if sc > best_score:
            best, best_score = k * coarse, sc
    centre = best
    n_fine = int(round(coarse / fine))
    for k in range(-n_fine, n_fine + 1):
        theta = centre + k * fine
        if k == 0:
            continue
        sc = _closeness(x, y, theta, d0)
        if sc > best_score:
            best, best_score = theta, sc
    return best % (0.5 * np.pi)


@njit(cache=True)
def fit_rectangles(
    xy: np.ndarray,
    members: np.ndarray,
    start: np.ndarray,
    objects: np.ndarray,
    cfg: tuple[float, float, float, float],
) -> np.ndarray:
    """Tightest L-shape rectangle of each listed object's points.

    ``xy`` (P, 2) are the x/y offsets from the sensor (network axes, m); object k's points are
    ``xy[members[start[k]:start[k + 1]]]``. ``cfg`` = (merge cell m, d0 m, coarse step rad,
    fine step rad). Returns (len(objects), 5): heading theta in [0, pi/2) (rad) of the first
    box axis, and the low/high bounds (m) of the points' projections on the first axis
    (cos theta, sin theta) and on the second (-sin theta, cos theta).
    """
    out = np.empty((len(objects), 5))
    for o in range(len(objects)):
        k = objects[o]
        rows = members[start[k] : start[k + 1]]
        x, y = _merge(xy[rows, 0], xy[rows, 1], cfg[0])
        theta = _best_heading(x, y, (cfg[1], cfg[2], cfg[3]))
        c, s = np.cos(theta), np.sin(theta)
        a = c * x + s * y
        b = -s * x + c * y
        out[o] = theta, a.min(), a.max(), b.min(), b.max()
    return out


def _complete_axis(lo: np.ndarray, hi: np.ndarray, prior: np.ndarray) -> np.ndarray:
    """Centre (m) along one box axis, with the sensor at 0 on that axis, after growing the
    visible span [lo, hi] to ``prior`` where it is shorter: away from the sensor when the
    sensor sees the face at one end (it lies beyond that end), else evenly about the
    visible middle (the sensor is beside the object: nothing tells which end is cut)."""
    grow = np.maximum(prior - (hi - lo), 0.0)
    shift = np.where(lo > 0, grow, np.where(hi < 0, -grow, 0.0))
    return (lo + hi) / 2 + shift / 2


def complete_boxes(
    rect: np.ndarray,
    prior_length: np.ndarray,
    prior_width: np.ndarray,
    sensor_heading: float,
    margin_m: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grow fitted rectangles to the class's size prior where fewer than all sides are seen.

    ``rect`` is fit_rectangles' output (offsets from the sensor, network axes); priors (m) are
    nan for objects without one (their box stays the visible one). Which box axis is the
    length: the longer visible extent when it exceeds the prior width by ``margin_m``, else
    (a box no longer than a vehicle is wide: an end face, or a short piece of a side) the axis
    nearer the sensor's heading ``sensor_heading`` (rad, network frame), because traffic
    mostly runs parallel to the ego. Returns the box centres (N, 2) as offsets from the sensor
    (network axes, m), the heading of the length axis in the network frame (rad, in
    [-pi/2, pi/2)), and the box length and width (N, 2), m (at least the visible extents).
    """
    theta, lo1, hi1, lo2, hi2 = rect.T
    ext1, ext2 = hi1 - lo1, hi2 - lo2
    near_x = np.abs(np.sin(theta - sensor_heading)) <= np.sqrt(0.5)  # axis 1 nearer heading
    long1 = ext1 >= ext2
    clear = np.maximum(ext1, ext2) > prior_width + margin_m
    first_is_length = np.where(clear, long1, near_x)
    first_is_length = np.where(np.isnan(prior_length), long1, first_is_length)
    p1 = np.nan_to_num(np.where(first_is_length, prior_length, prior_width))
    p2 = np.nan_to_num(np.where(first_is_length, prior_width, prior_length))
    a = _complete_axis(lo1, hi1, p1)
    b = _complete_axis(lo2, hi2, p2)
    c, s = np.cos(theta), np.sin(theta)
    centre = np.stack([c * a - s * b, s * a + c * b], 1)
    size1, size2 = np.maximum(ext1, p1), np.maximum(ext2, p2)
    heading = np.where(first_is_length, theta, theta + np.pi / 2)
    heading = (heading + np.pi / 2) % np.pi - np.pi / 2
    dims = np.where(
        first_is_length[:, None], np.stack([size1, size2], 1), np.stack([size2, size1], 1)
    )
    return centre, heading, dims
