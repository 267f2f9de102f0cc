"""Many 3D polylines packed into one array, with vectorised offsets, lengths and dashing.

Coordinates are SUMO network metres (x, y, z up). Left is the left of the direction of travel
along a polyline (counter-clockwise from it, seen from above).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Polylines:
    """``points[offsets[k]:offsets[k + 1]]`` is polyline k; every polyline has >= 2 points."""

    points: np.ndarray  # (P, 3) float64
    offsets: np.ndarray  # (L + 1,) int64, offsets[0] == 0, offsets[-1] == P

    @staticmethod
    def pack(lines: Sequence[np.ndarray]) -> Polylines:
        """Pack (n_k, 3) arrays; lines with fewer than two points are left out."""
        kept = [np.asarray(ln, dtype=np.float64) for ln in lines if len(ln) >= 2]
        counts = np.array([len(ln) for ln in kept], dtype=np.int64)
        offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        points = np.concatenate(kept) if kept else np.zeros((0, 3))
        return Polylines(points, offsets)

    def __len__(self) -> int:
        return len(self.offsets) - 1

    def line(self, k: int) -> np.ndarray:
        """(n, 3) points of polyline k."""
        return self.points[self.offsets[k] : self.offsets[k + 1]]

    @property
    def segment_mask(self) -> np.ndarray:
        """(P - 1,) True where points i and i + 1 belong to the same polyline."""
        mask = np.ones(max(len(self.points) - 1, 0), dtype=bool)
        ends = self.offsets[1:-1] - 1
        mask[ends] = False
        return mask

    @property
    def is_first(self) -> np.ndarray:
        """(P,) True at the first point of each polyline."""
        first = np.zeros(len(self.points), dtype=bool)
        first[self.offsets[:-1]] = True
        return first

    @property
    def is_last(self) -> np.ndarray:
        """(P,) True at the last point of each polyline."""
        last = np.zeros(len(self.points), dtype=bool)
        last[self.offsets[1:] - 1] = True
        return last

    def left_normals(self, max_miter: float = 4.0) -> np.ndarray:
        """(P, 2) mitred left normals: offsetting by ``d * normal`` keeps segments d apart.

        At a corner the unit bisector is scaled by 1 / cos(half the turn), capped at
        ``max_miter`` so that hairpins do not throw points far away.
        """
        p = self.points[:, :2]
        d = p[1:] - p[:-1]
        length = np.hypot(d[:, 0], d[:, 1])
        valid = self.segment_mask & (length > 0)
        seg_n = np.zeros_like(d)
        seg_n[valid] = np.stack([-d[valid, 1], d[valid, 0]], 1) / length[valid, None]
        n_prev = np.zeros_like(p)
        n_next = np.zeros_like(p)
        n_prev[1:] = seg_n
        n_next[:-1] = seg_n
        bisector = n_prev + n_next
        norm = np.hypot(bisector[:, 0], bisector[:, 1])
        reference = np.where(np.any(n_next != 0, axis=1, keepdims=True), n_next, n_prev)
        unit = np.where(
            norm[:, None] > 1e-9, bisector / np.maximum(norm, 1e-12)[:, None], reference
        )
        cos_half = np.sum(unit * reference, axis=1)
        return unit / np.maximum(cos_half, 1.0 / max_miter)[:, None]

    def offset(self, distance: np.ndarray | float, normals: np.ndarray | None = None) -> np.ndarray:
        """(P, 3) points moved ``distance`` metres to the left (negative: right); z kept."""
        n = self.left_normals() if normals is None else normals
        out = self.points.copy()
        out[:, :2] += (
            n * np.broadcast_to(np.asarray(distance, dtype=np.float64), (len(out),))[:, None]
        )
        return out

    def arc_length(self) -> np.ndarray:
        """(P,) 3D distance along each polyline from its first point, m."""
        seg = np.linalg.norm(self.points[1:] - self.points[:-1], axis=1) * self.segment_mask
        s = np.concatenate([[0.0], np.cumsum(seg)])
        return s - np.repeat(s[self.offsets[:-1]], np.diff(self.offsets))

    def lengths(self) -> np.ndarray:
        """(L,) 3D length of each polyline, m."""
        return self.arc_length()[self.offsets[1:] - 1]

    def dashes(
        self, dash: np.ndarray, gap: np.ndarray, values: np.ndarray | None = None
    ) -> tuple[Polylines, np.ndarray, np.ndarray | None]:
        """Cut each polyline k into pieces of ``dash[k]`` metres every ``dash[k] + gap[k]``.

        Returns the pieces, for each piece the index of the polyline it came from, and
        ``values`` ((P, m) per-point attributes) interpolated onto the pieces' points. Dashes
        start at each polyline's first point; a last piece shorter than the dash is kept.
        """
        cols = self.points if values is None else np.column_stack([self.points, values])
        s = self.arc_length()
        lengths = self.lengths()
        # One increasing station over all polylines, with a gap between them so that no
        # interpolation reaches from one polyline into the next.
        shift = np.concatenate([[0.0], np.cumsum(lengths + 1.0)[:-1]])
        station = s + np.repeat(shift, np.diff(self.offsets))
        period = dash + gap
        count = np.ceil(lengths / period).astype(np.int64)
        owner = np.repeat(np.arange(len(self)), count)
        j = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        start = j * period[owner]
        stop = np.minimum(start + dash[owner], lengths[owner])
        keep = stop - start >= 1e-3
        owner, start, stop = (
            owner[keep],
            start[keep] + shift[owner[keep]],
            stop[keep] + shift[owner[keep]],
        )
        lo = np.searchsorted(station, start, side="right")
        hi = np.searchsorted(station, stop, side="left")
        inner = np.maximum(hi - lo, 0)
        sizes = inner + 2
        offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        # Stations of every output point: piece start, the vertices inside, piece end.
        first = offsets[:-1]
        at = np.empty(offsets[-1])
        at[first] = start
        at[offsets[1:] - 1] = stop
        rank = np.arange(offsets[-1]) - np.repeat(first, sizes)
        middle = (rank > 0) & (rank < np.repeat(sizes, sizes) - 1)
        at[middle] = station[(np.repeat(lo, sizes) + rank - 1)[middle]]
        out = np.column_stack([np.interp(at, station, c) for c in cols.T])
        pieces = Polylines(out[:, :3].copy(), offsets)
        extra = None if values is None else out[:, 3:]
        return pieces, owner, extra


def clean_polyline(points: np.ndarray, min_step: float = 5e-3) -> np.ndarray:
    """Drop points closer than ``min_step`` metres (in plan) to the previous kept point.

    The last point is always kept (replacing a kept point too close to it), so the
    polyline still ends where it did.
    """
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 2:
        return p
    step = np.hypot(*(p[1:, :2] - p[:-1, :2]).T)
    if np.all(step >= min_step):
        return p
    keep = [0]
    for i in range(1, len(p)):
        if np.hypot(*(p[i, :2] - p[keep[-1], :2])) >= min_step:
            keep.append(i)
    if keep[-1] != len(p) - 1:
        if len(keep) > 1:
            keep[-1] = len(p) - 1
        else:
            keep.append(len(p) - 1)
    out = p[keep]
    if len(out) == 2 and np.hypot(*(out[1, :2] - out[0, :2])) < min_step:
        return out[:1]
    return out
