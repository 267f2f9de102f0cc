"""A road alignment (plan-view centre line) built from its curvature, plus height and banking.

The alignment is a chain of elements with linearly varying curvature: straights (0), circular
arcs (1/R) and clothoid transitions between them (the JAMA Annex A "transition section").
Station ``s`` is metres along the alignment; ``lateral`` is metres to the left of it. Heading
in radians counter-clockwise from +x; curvature positive for left turns.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Element:
    """One alignment element: length in m, curvature at its start and end in 1/m."""

    length: float
    k_start: float
    k_end: float

    @property
    def is_straight(self) -> bool:
        return self.k_start == 0.0 and self.k_end == 0.0


@dataclass(frozen=True, eq=False)
class Alignment:
    """Centre line sampled on a fine station grid; query any station by interpolation."""

    elements: tuple[Element, ...]
    s: np.ndarray  # (n,) station grid, m
    xy: np.ndarray  # (n, 2) m
    heading: np.ndarray  # (n,) rad
    curvature: np.ndarray  # (n,) 1/m

    @staticmethod
    def from_elements(
        elements: list[Element],
        start: tuple[float, float] = (0.0, 0.0),
        heading: float = 0.0,
        step: float = 0.25,
    ) -> Alignment:
        """Integrate heading and position along the elements on a ``step``-metre grid."""
        bounds = np.concatenate([[0.0], np.cumsum([e.length for e in elements])])
        s = np.unique(np.concatenate([np.arange(0.0, bounds[-1], step), bounds]))
        k = np.zeros_like(s)
        for e, s0 in zip(elements, bounds[:-1], strict=True):
            inside = (s >= s0) & (s <= s0 + e.length)
            k[inside] = e.k_start + (e.k_end - e.k_start) * (s[inside] - s0) / e.length
        ds = np.diff(s)
        h = heading + np.concatenate([[0.0], np.cumsum(0.5 * (k[1:] + k[:-1]) * ds)])
        # Position: midpoint-heading rule per step; exact for arcs up to O(ds^3 k^2).
        hm = 0.5 * (h[1:] + h[:-1])
        dx = np.concatenate([[0.0], np.cumsum(np.cos(hm) * ds)])
        dy = np.concatenate([[0.0], np.cumsum(np.sin(hm) * ds)])
        xy = np.column_stack([start[0] + dx, start[1] + dy])
        return Alignment(tuple(elements), s, xy, h, k)

    def element_bounds(self) -> np.ndarray:
        """(len(elements) + 1,) stations where elements start and end."""
        return np.concatenate([[0.0], np.cumsum([e.length for e in self.elements])])

    def frame(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(n, 2) centre-line points and (n,) headings at stations ``s``."""
        s = np.asarray(s, dtype=np.float64)
        xy = np.column_stack(
            [np.interp(s, self.s, self.xy[:, 0]), np.interp(s, self.s, self.xy[:, 1])]
        )
        return xy, np.interp(s, self.s, self.heading)

    def curvature_at(self, s: np.ndarray) -> np.ndarray:
        return np.interp(s, self.s, self.curvature)

    def point(self, s: np.ndarray, lateral: np.ndarray | float) -> np.ndarray:
        """(n, 2) points ``lateral`` metres left of the centre line at stations ``s``."""
        xy, h = self.frame(s)
        lat = np.broadcast_to(np.asarray(lateral, dtype=np.float64), h.shape)
        return xy + lat[:, None] * np.column_stack([-np.sin(h), np.cos(h)])

    def stations(
        self, s0: float, s1: float, step: float, dense: np.ndarray | None = None
    ) -> np.ndarray:
        """Stations from s0 to s1: element bounds, and every ``step`` m on curved elements.

        ``dense`` (pairs of stations, (m, 2)) adds more intervals sampled every ``step`` m,
        for example where the cross-section or a ramp's offset changes.
        """
        bounds = self.element_bounds()
        pts = [np.array([s0, s1]), bounds[(bounds > s0) & (bounds < s1)]]
        intervals = [
            (a, a + e.length)
            for e, a in zip(self.elements, bounds[:-1], strict=True)
            if not e.is_straight
        ]
        if dense is not None:
            intervals += [tuple(row) for row in np.asarray(dense).reshape(-1, 2)]
        for a, b in intervals:
            lo, hi = max(a, s0), min(b, s1)
            if hi > lo:
                n = int(np.ceil((hi - lo) / step))
                pts.append(np.linspace(lo, hi, n + 1))
        return np.unique(np.concatenate(pts))
