"""Vectorised distance, headway and TTC measures between actor pairs (numpy arrays).

Inputs are per-pair arrays: centres (N, 2), headings (N,), lengths / widths (N,), speeds.
Entity frame of actor A: x along its heading, y to its left. Freespace measures are between
the oriented bounding boxes; others between reference points. Unsigned distances, metres.
"""

from __future__ import annotations

import numpy as np


def box_corners(c: np.ndarray, h: np.ndarray, length: np.ndarray, width: np.ndarray) -> np.ndarray:
    """(N, 4, 2) corners of oriented boxes."""
    ca, sa = np.cos(h), np.sin(h)
    fwd = np.stack([ca, sa], 1) * (length / 2)[:, None]
    left = np.stack([-sa, ca], 1) * (width / 2)[:, None]
    return np.stack([c + fwd + left, c - fwd + left, c - fwd - left, c + fwd - left], 1)


def to_frame(p: np.ndarray, origin: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Points (N, ..., 2) in the frame at ``origin`` (N, 2) with heading ``h`` (N,)."""
    d = p - origin.reshape(origin.shape[0], *([1] * (p.ndim - 2)), 2)
    c = np.cos(h).reshape(-1, *([1] * (p.ndim - 2)))
    s = np.sin(h).reshape(-1, *([1] * (p.ndim - 2)))
    return np.stack([d[..., 0] * c + d[..., 1] * s, -d[..., 0] * s + d[..., 1] * c], -1)


def axis_gaps(
    ca: np.ndarray,
    ha: np.ndarray,
    la: np.ndarray,
    wa: np.ndarray,
    corners_b: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Freespace gaps along A's x and y axes to box B (given by its corners), and where B's
    extent lies along x: (gap_x, gap_y, min_x, max_x) in A's frame (gaps 0 when the extents
    overlap)."""
    local = to_frame(corners_b, ca, ha)
    xmin, xmax = local[..., 0].min(1), local[..., 0].max(1)
    ymin, ymax = local[..., 1].min(1), local[..., 1].max(1)
    gx = np.maximum(0.0, np.maximum(xmin - la / 2, -la / 2 - xmax))
    gy = np.maximum(0.0, np.maximum(ymin - wa / 2, -wa / 2 - ymax))
    return gx, gy, xmin, xmax


def box_distance(corners_a: np.ndarray, corners_b: np.ndarray) -> np.ndarray:
    """(N,) shortest distance between convex quadrilaterals; 0 when they overlap."""
    d1 = _corner_to_edges(corners_a, corners_b)
    d2 = _corner_to_edges(corners_b, corners_a)
    dist = np.minimum(d1, d2)
    return np.where(_overlap(corners_a, corners_b), 0.0, dist)


def _corner_to_edges(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    a = q[:, None, :, :]  # (N, 1, 4e, 2)
    ab = np.roll(q, -1, axis=1)[:, None, :, :] - a
    ap = p[:, :, None, :] - a  # (N, 4p, 4e, 2)
    denom = np.maximum((ab * ab).sum(-1), 1e-12)
    u = np.clip((ap * ab).sum(-1) / denom, 0.0, 1.0)
    d = ap - u[..., None] * ab
    return np.sqrt((d * d).sum(-1).min(axis=(1, 2)))


def _overlap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Separating-axis test on the four edge normals of two rectangles."""
    axes = np.concatenate([a[:, 1:3] - a[:, 0:2], b[:, 1:3] - b[:, 0:2]], axis=1)  # (N, 4, 2)
    pa = (axes[:, :, None, :] * a[:, None, :, :]).sum(-1)  # (N, 4 axes, 4 corners)
    pb = (axes[:, :, None, :] * b[:, None, :, :]).sum(-1)
    sep = (pa.max(2) < pb.min(2)) | (pb.max(2) < pa.min(2))
    return ~sep.any(1)
