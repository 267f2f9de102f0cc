"""A path sampled densely enough to interpolate linearly: points in the plane with the distance
along the path, the heading an entity on it faces, and optionally the time it is there.

Network x, y in metres, headings in radians from +x, s in metres from the path's start, times
in seconds of scenario time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class SampledPath:
    """``xy`` (n, 2) points, ``s`` (n,) distance along the path, ``h`` (n,) heading at each
    point, ``times`` (n,) s or None (untimed)."""

    xy: np.ndarray
    s: np.ndarray
    h: np.ndarray
    times: np.ndarray | None = None

    @staticmethod
    def through(
        xy: np.ndarray,
        h: np.ndarray | None = None,
        times: np.ndarray | None = None,
        s: np.ndarray | None = None,
    ) -> SampledPath:
        """The path through ``xy`` (repeated points dropped); headings ``h`` per point, else
        the direction of travel; ``s`` the arc length at each point of a curve sampled by
        chords (else the chords' lengths summed)."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        seg = np.linalg.norm(np.diff(xy, axis=0), axis=1)
        keep = np.concatenate([[True], seg > 1e-9])
        xy = xy[keep]
        h = None if h is None else np.asarray(h, dtype=float)[keep]
        times = None if times is None else np.asarray(times, dtype=float)[keep]
        if s is None:
            s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
        else:
            s = np.asarray(s, dtype=float)[keep]
        if h is None:
            h = _travel_headings(xy)
        return SampledPath(xy, s, h, times)

    @property
    def length(self) -> float:
        """Metres from start to end."""
        return float(self.s[-1])

    def pose(self, s: float, t: float = 0.0) -> tuple[float, float, float]:
        """(x, y, heading) at ``s`` m along the path (clamped to it), ``t`` m to its left.
        Between points the heading turns linearly (the shorter way)."""
        s = min(max(s, 0.0), self.length)
        k = int(np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, max(len(self.s) - 2, 0)))
        if len(self.s) == 1:
            x, y, h = self.xy[0, 0], self.xy[0, 1], self.h[0]
        else:
            span = self.s[k + 1] - self.s[k]
            f = (s - self.s[k]) / span if span > 0 else 0.0
            x = self.xy[k, 0] + f * (self.xy[k + 1, 0] - self.xy[k, 0])
            y = self.xy[k, 1] + f * (self.xy[k + 1, 1] - self.xy[k, 1])
            h = self.h[k] + f * math.remainder(self.h[k + 1] - self.h[k], 2 * math.pi)
        if t:
            d = self.direction(s)
            x, y = x - t * math.sin(d), y + t * math.cos(d)
        return float(x), float(y), math.remainder(float(h), 2 * math.pi)

    def direction(self, s: float) -> float:
        """Direction of travel at ``s`` (rad): of the segment holding it."""
        if len(self.s) < 2:
            return float(self.h[0])
        k = int(np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, len(self.s) - 2))
        d = self.xy[k + 1] - self.xy[k]
        return math.atan2(d[1], d[0])

    def time_at(self, s: float) -> float:
        """Scenario time (s) at ``s`` m (the path must be timed)."""
        return float(np.interp(s, self.s, self.times))

    def s_at_time(self, time: float) -> float:
        """Distance along the path (m) at scenario time ``time`` (the path must be timed)."""
        return float(np.interp(time, self.times, self.s))

    def project(self, x: float, y: float) -> tuple[float, float]:
        """(s, t) of the point nearest to (``x``, ``y``) on the path, t to its left (m)."""
        if len(self.s) < 2:
            return 0.0, 0.0
        a, b = self.xy[:-1], self.xy[1:]
        d = b - a
        seg2 = np.maximum((d * d).sum(1), 1e-18)
        p = np.array([x, y])
        f = np.clip(((p - a) * d).sum(1) / seg2, 0.0, 1.0)
        foot = a + f[:, None] * d
        dist = np.hypot(*(p - foot).T)
        k = int(np.argmin(dist))
        s = float(self.s[k] + f[k] * (self.s[k + 1] - self.s[k]))
        cross = d[k, 0] * (y - a[k, 1]) - d[k, 1] * (x - a[k, 0])
        return s, float(math.copysign(dist[k], cross))


def _travel_headings(xy: np.ndarray) -> np.ndarray:
    """Direction of travel at each point (the last point: of the last segment)."""
    if len(xy) < 2:
        return np.zeros(len(xy))
    d = np.diff(xy, axis=0)
    h = np.arctan2(d[:, 1], d[:, 0])
    return np.concatenate([h, h[-1:]])
