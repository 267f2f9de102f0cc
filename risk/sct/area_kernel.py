"""Point in area (the carriageway) without GEOS for the points it can decide exactly.

The SCT metrics ask, for thousands of predicted pedestrian positions per step, whether each
lies inside the carriageway (shapely.contains_xy: the interior, the boundary excluded). For a
valid polygon or multipolygon that is the parity of a ray's crossings with its rings, exactly
as GEOS's point locator counts them. Here the parity is counted in a compiled loop with every
orientation sign decided by Shewchuk's error bound for orient2d: a point whose sign the bound
cannot guarantee (on an edge, a vertex, or within rounding of one) is left undecided and asked
of shapely. So every answer is GEOS's, bit for bit (tests/test_sct_contact_kernel.py), and
GEOS is called only for points on or within ~1e-15 m of the boundary.

Frames and units: network coordinates in metres.
"""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit

# Shewchuk's ccwerrboundA, (3 + 16 eps) eps with eps = 2^-53: |det| above it times the
# permanent means the floating-point orient2d has the exact sign
_CCW_ERROR = (3.0 + 16.0 * 2.0**-53) * 2.0**-53


@njit(cache=True)
def locate_xy(points: np.ndarray, ring_xy: np.ndarray, ring_start: np.ndarray) -> np.ndarray:
    """(n,) int8 per point (``points`` (n, 2) m): 1 inside the area bounded by the closed
    rings (``ring_xy`` (E, 2), ring r's vertices ``ring_start[r]`` .. ``ring_start[r+1] -
    1``, first = last), 0 outside, -1 undecided (on the boundary or within rounding of it)."""
    out = np.empty(len(points), np.int8)
    for i in range(len(points)):
        px, py = points[i, 0], points[i, 1]
        crossings = 0
        undecided = False
        for r in range(len(ring_start) - 1):
            for e in range(ring_start[r], ring_start[r + 1] - 1):
                x1, y1 = ring_xy[e, 0], ring_xy[e, 1]
                x2, y2 = ring_xy[e + 1, 0], ring_xy[e + 1, 1]
                if (y1 > py and y2 > py) or (y1 < py and y2 < py):
                    continue  # wholly above or below the point's row
                straddles = (y1 > py) != (y2 > py)  # half-open: one end above, one not
                if px < min(x1, x2):
                    crossings += straddles  # wholly right of the point: the ray hits it
                    continue
                if px > max(x1, x2):
                    continue
                # the point lies in the edge's bounding box: on it, or on one side for sure?
                left = (x1 - px) * (y2 - py)
                right = (y1 - py) * (x2 - px)
                det = left - right
                if abs(det) <= _CCW_ERROR * (abs(left) + abs(right)):
                    undecided = True
                    break
                if straddles and (det > 0.0) == (y2 > y1):
                    crossings += 1  # left of an upward edge or right of a downward one
            if undecided:
                break
        out[i] = -1 if undecided else crossings & 1
    return out


class AreaTest:
    """shapely.contains_xy on one area, counted in locate_xy where the area is a valid
    (multi)polygon; GEOS answers the undecided points (and everything for other areas)."""

    def __init__(self, area: shapely.Geometry) -> None:
        self.area = area
        self._rings: tuple[np.ndarray, np.ndarray] | None = None
        if shapely.get_type_id(area) in (3, 6) and not area.is_empty and shapely.is_valid(area):
            rings = shapely.get_rings(shapely.get_parts(area))
            coords = [shapely.get_coordinates(r) for r in rings]
            start = np.cumsum([0] + [len(c) for c in coords])
            self._rings = (np.ascontiguousarray(np.concatenate(coords)), start.astype(np.int64))

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(...) bool: the ``points`` (..., 2) m strictly inside the area."""
        if self._rings is None:
            return shapely.contains_xy(self.area, points[..., 0], points[..., 1])
        flat = np.ascontiguousarray(points, float).reshape(-1, 2)
        where = locate_xy(flat, *self._rings)
        out = where == 1
        ask = np.flatnonzero(where < 0)
        if len(ask):
            out[ask] = shapely.contains_xy(self.area, flat[ask, 0], flat[ask, 1])
        return out.reshape(points.shape[:-1])
