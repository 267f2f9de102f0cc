"""Lane frames: road coordinates along one lane's centre line, ``s`` metres along it and ``d``
metres to its left, mapped to network x, y (metres) and the centre line's heading (radians
counter-clockwise from +x)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RoadFrame:
    """Road coordinates along a lane centre line (polyline) in network metres."""

    points: np.ndarray  # (K, 2)
    cum: np.ndarray  # (K,) arc length at each point
    edge: str
    lane_index: int

    @staticmethod
    def from_points(points: np.ndarray, edge: str, lane_index: int) -> RoadFrame:
        """The frame along the centre-line polyline ``points`` (K, 2) m of lane ``lane_index``
        of ``edge`` (a lane of a net: hiyari.net.road.network.RoadNetwork.lane_frame)."""
        pts = np.asarray(points, dtype=float)
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        return RoadFrame(pts, np.concatenate([[0.0], np.cumsum(seg)]), edge, lane_index)

    @property
    def length(self) -> float:
        return float(self.cum[-1])

    def to_xy(self, s: float, d: float) -> tuple[float, float, float]:
        """(x, y, heading of the centre line) at arc length ``s``, offset ``d`` to the left."""
        k = int(np.clip(np.searchsorted(self.cum, s, side="right") - 1, 0, len(self.cum) - 2))
        p0, p1 = self.points[k], self.points[k + 1]
        seg = self.cum[k + 1] - self.cum[k]
        u = (p1 - p0) / seg
        p = p0 + u * (s - self.cum[k])
        left = np.array([-u[1], u[0]])
        x, y = p + left * d
        return float(x), float(y), math.atan2(u[1], u[0])
