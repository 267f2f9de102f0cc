"""What entity conditions measure at one step, one condition row at a time, compiled.

A row is one (condition, triggering entity) pair. Rows are compiled into one table
(:class:`EntityRows`) and measured by :mod:`trigger_kernel` in one compiled loop, each row by
the scalar functions here: pair measures (relative distance, headway, TTC to an entity),
single-entity measures (speed, acceleration, relative speed), durations (standstill, end of
road) and point measures (distance, reach, TTC to a position). The geometry is the
kinematics kernel's (:mod:`hiyari.kinematics`), written out per scalar with the same operations
in the same order, so the values are the kernel's bit for bit (tests/test_engine_kernel.py).
Rows whose entities are absent measure NaN, which no rule holds for.

Frames and units: world x, y in metres, headings in radians from world +x, speeds m/s, times
s. An entity's ``centre`` is its bounding-box centre, ``ref`` its reference point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from hiyari.bridge.scenario.model.positions import LanePosition, RoadPosition, WorldPosition

#: Speed below which an actor stands still, m/s.
STANDSTILL_SPEED = 0.01
#: Row kinds, by the group that measures them.
REL_DIST, HEADWAY, TTC = 0, 1, 2
SPEED, ACCEL, REL_SPEED = 3, 4, 5
STANDSTILL, END_OF_ROAD = 6, 7
DISTANCE, REACH, TTC_POINT = 8, 9, 10
COLLISION = 11
DURATION_KINDS = (STANDSTILL, END_OF_ROAD)
POINT_KINDS = (DISTANCE, REACH, TTC_POINT)
#: Positions that do not depend on where the entities are: resolved once.
FIXED_POSITIONS = (WorldPosition, LanePosition, RoadPosition)


@njit(cache=True, inline="always")
def holds(measured: float, value: float, rule: int) -> bool:
    """Whether ``measured`` satisfies rule code ``rule`` (index into Rule: greaterThan,
    lessThan, equalTo, greaterOrEqual, lessOrEqual, notEqualTo) against ``value``; never for
    a NaN measure."""
    if measured != measured:
        return False
    if rule == 0:
        return measured > value
    if rule == 1:
        return measured < value
    if rule == 2:
        return measured == value
    if rule == 3:
        return measured >= value
    if rule == 4:
        return measured <= value
    return measured != value


@dataclass
class EntityRows:
    """Every entity-condition row: owning condition, triggering entity ``a``, reference entity
    ``b`` (-1: none), value and rule code, kind, freespace, distance type (0 euclidean,
    1 longitudinal, 2 lateral), road coordinates (else entity) and the condition body."""

    owner: np.ndarray
    a: np.ndarray
    b: np.ndarray
    value: np.ndarray
    rule: np.ndarray
    kind: np.ndarray
    freespace: np.ndarray
    dtype: np.ndarray
    road: np.ndarray
    body: list[object]

    def __len__(self) -> int:
        return len(self.owner)


# ---------------------------------------------------------------------------------- geometry
@njit(cache=True, inline="always")
def _unrotate(x: float, y: float, c: float, s: float) -> tuple[float, float]:
    """kinematics.unrotate_xy for one vector, with the cos ``c`` and sin ``s`` of the
    heading."""
    return x * c + y * s, -x * s + y * c


@njit(cache=True, inline="always")
def _max0(x: float) -> float:
    """np.maximum(0.0, x): NaN stays NaN."""
    return x if (x > 0.0 or x != x) else 0.0


@njit(cache=True, inline="always")
def _outside(x: float, y: float, half_x: float, half_y: float) -> float:
    """kinematics._outside for one point."""
    lx, ly = _max0(abs(x) - half_x), _max0(abs(y) - half_y)
    if ly == 0.0:  # C99 F.9.4.3: hypot(x, 0) is fabs(x), exactly; saves the call
        return lx
    if lx == 0.0:
        return ly
    return math.hypot(lx, ly)


@njit(cache=True, inline="always")
def footprint_distance(
    ax_: float,
    ay_: float,
    ha: float,
    length_a: float,
    width_a: float,
    bx_: float,
    by_: float,
    hb: float,
    length_b: float,
    width_b: float,
) -> float:
    """kinematics.footprint_distance for one pair of rectangles (centres m, headings rad)."""
    return _footprint_distance(
        ax_, ay_, ha, math.cos(ha), math.sin(ha), length_a, width_a,
        bx_, by_, hb, math.cos(hb), math.sin(hb), length_b, width_b,
    )  # fmt: skip


@njit(cache=True, inline="always")
def _footprint_distance(
    ax_: float,
    ay_: float,
    ha: float,
    cha: float,
    sha: float,
    length_a: float,
    width_a: float,
    bx_: float,
    by_: float,
    hb: float,
    chb: float,
    shb: float,
    length_b: float,
    width_b: float,
) -> float:
    """footprint_distance with the cos and sin of both headings given."""
    dx, dy = bx_ - ax_, by_ - ay_
    la, wa, lb, wb = 0.5 * length_a, 0.5 * width_a, 0.5 * length_b, 0.5 * width_b
    c, s = math.cos(hb - ha), math.sin(hb - ha)
    bx, by = _unrotate(dx, dy, cha, sha)
    ax, ay = _unrotate(-dx, -dy, chb, shb)
    lbc, lbs, wbc, wbs = lb * c, lb * s, wb * c, wb * s
    lac, las, wac, was = la * c, la * s, wa * c, wa * s
    ac, as_ = abs(c), abs(s)
    apart = (abs(bx) > la + lb * ac + wb * as_) or (abs(by) > wa + lb * as_ + wb * ac)
    apart = apart or (abs(ax) > lb + la * ac + wa * as_) or (abs(ay) > wb + la * as_ + wa * ac)
    if not apart:
        return 0.0
    b_in_a, a_in_b = math.inf, math.inf
    for sx, sy in ((1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)):
        xb, yb = bx + sx * lbc - sy * wbs, by + sx * lbs + sy * wbc
        xa, ya = ax + sx * lac + sy * was, ay - sx * las + sy * wac
        b_in_a = min(b_in_a, _outside(xb, yb, la, wa))
        a_in_b = min(a_in_b, _outside(xa, ya, lb, wb))
    return min(b_in_a, a_in_b)


# ---------------------------------------------------------------------------------- pairs
@njit(cache=True, inline="always")
def _entity_distance(
    a: int,
    b: int,
    fs: bool,
    dtype: int,
    centre: np.ndarray,
    ref: np.ndarray,
    heading: np.ndarray,
    cos_h: np.ndarray,
    sin_h: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
) -> float:
    """Distance (m) of B from A in A's frame, by distance type: between the reference points,
    or the boxes' gap with ``fs`` (freespace)."""
    ha, la, wa, ca, sa = heading[a], length[a], width[a], cos_h[a], sin_h[a]
    if dtype == 0 and fs:
        return _footprint_distance(
            centre[a, 0], centre[a, 1], ha, ca, sa, la, wa,
            centre[b, 0], centre[b, 1], heading[b], cos_h[b], sin_h[b], length[b], width[b],
        )  # fmt: skip
    if not fs:
        rx, ry = _unrotate(ref[b, 0] - ref[a, 0], ref[b, 1] - ref[a, 1], ca, sa)
        return math.hypot(rx, ry) if dtype == 0 else (abs(rx) if dtype == 1 else abs(ry))
    bx, by = _unrotate(centre[b, 0] - centre[a, 0], centre[b, 1] - centre[a, 1], ca, sa)
    # footprint_extent of B in A's frame
    c, s = abs(math.cos(heading[b] - ha)), abs(math.sin(heading[b] - ha))
    if dtype == 1:
        return _max0(abs(bx) - 0.5 * la - (length[b] * c + width[b] * s) / 2)
    return _max0(abs(by) - 0.5 * wa - (length[b] * s + width[b] * c) / 2)


@njit(cache=True, inline="always")
def _road_distance(
    a: int,
    b: int,
    fs: bool,
    dtype: int,
    length: np.ndarray,
    width: np.ndarray,
    road_s: np.ndarray,
    road_t: np.ndarray,
    road_dir: np.ndarray,
) -> float:
    """Distance (m) of B from A in road coordinates, by distance type."""
    ds = (road_s[b] - road_s[a]) * road_dir[a]
    dt = road_t[b] - road_t[a]
    lon, lat = abs(ds), abs(dt)
    if fs:
        lon = _max0(abs(ds) - 0.5 * (length[a] + length[b]))
        lat = _max0(abs(dt) - 0.5 * (width[a] + width[b]))
    if dtype == 1:
        return lon
    if dtype == 2:
        return lat
    return math.hypot(lon, lat)


@njit(cache=True, inline="always")
def _sign(x: float) -> float:
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return x  # 0 or NaN, as np.sign


@njit(cache=True, inline="always")
def _closing(
    a: int,
    b: int,
    dtype: int,
    centre: np.ndarray,
    cos_h: np.ndarray,
    sin_h: np.ndarray,
    speed: np.ndarray,
) -> float:
    """Closing speed (m/s) of A and B along the measuring direction: A's axis (longitudinal /
    lateral) or the line between the centres (euclidean)."""
    ca, sa, va, vb = cos_h[a], sin_h[a], speed[a], speed[b]
    dvx, dvy = va * ca - vb * cos_h[b], va * sa - vb * sin_h[b]  # relative velocity
    rx, ry = centre[b, 0] - centre[a, 0], centre[b, 1] - centre[a, 1]
    n = max(math.hypot(rx, ry), 1e-9)
    if dtype == 1:
        dx, dy = ca, sa
    elif dtype == 2:
        dx, dy = -sa, ca
    else:
        dx, dy = rx / n, ry / n
    return (dvx * dx + dvy * dy) * _sign(rx * dx + ry * dy)


@njit(cache=True, inline="always")
def pair_measure(
    kind: int,
    a: int,
    b: int,
    fs: bool,
    dtype: int,
    road: bool,
    present: np.ndarray,
    centre: np.ndarray,
    ref: np.ndarray,
    heading: np.ndarray,
    cos_h: np.ndarray,
    sin_h: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    speed: np.ndarray,
    road_s: np.ndarray,
    road_t: np.ndarray,
    road_dir: np.ndarray,
) -> float:
    """Relative distance (m), time headway (s) or TTC (s) of A to B (NaN: one absent).
    ``cos_h`` / ``sin_h``: cos and sin of each entity's heading. The distance is measured
    only when the headway or TTC needs it (B ahead and A moving; closing)."""
    if b < 0 or not present[a] or not present[b]:
        return math.nan
    if kind == HEADWAY:
        if road:
            ahead = (road_s[b] - road_s[a]) * road_dir[a]
        else:
            ahead = (centre[b, 0] - centre[a, 0]) * cos_h[a] + (
                centre[b, 1] - centre[a, 1]
            ) * sin_h[a]  # B's centre along A's axis, as _unrotate
        v = speed[a]
        if not (ahead > 0 and v > 1e-6):
            return math.inf
    elif kind == TTC:
        closing = _closing(a, b, dtype, centre, cos_h, sin_h, speed)
        if not closing > 1e-9:
            return math.inf
    if road:
        dist = _road_distance(a, b, fs, dtype, length, width, road_s, road_t, road_dir)
    else:
        dist = _entity_distance(a, b, fs, dtype, centre, ref, heading, cos_h, sin_h, length, width)
    if kind == HEADWAY:
        return dist / max(speed[a], 1e-6)
    if kind == TTC:
        return dist / max(closing, 1e-9)
    return dist


@njit(cache=True, inline="always")
def ttc_above(
    a: int,
    b: int,
    value: float,
    centre: np.ndarray,
    cos_h: np.ndarray,
    sin_h: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    speed: np.ndarray,
) -> bool:
    """Whether the freespace euclidean TTC of present A to present B (``pair_measure``) is
    certainly infinite (not closing) or above ``value`` (s, below infinity), found without
    the footprint distance: the boxes' gap is at least the centres' distance less both
    half-diagonals (less a micrometre per metre, far above the rounding of either)."""
    closing = _closing(a, b, 0, centre, cos_h, sin_h, speed)
    if not closing > 1e-9:
        return True
    apart = math.hypot(centre[b, 0] - centre[a, 0], centre[b, 1] - centre[a, 1])
    gap = apart - 0.5 * (math.hypot(length[a], width[a]) + math.hypot(length[b], width[b]))
    margin = 1e-6 * (1.0 + apart)
    return gap - margin > 0.0 and gap - margin > value * closing * (1.0 + 1e-9)


# ---------------------------------------------------------------------------------- one entity
@njit(cache=True, inline="always")
def single_measure(
    kind: int, a: int, b: int, present: np.ndarray, speed: np.ndarray, accel: np.ndarray
) -> float:
    """Speed (m/s), acceleration (m/s^2) or speed relative to entity B (NaN: absent)."""
    if not present[a]:
        return math.nan
    if kind == SPEED:
        return speed[a]
    if kind == ACCEL:
        return accel[a]
    if b < 0 or not present[b]:
        return math.nan
    return speed[a] - speed[b]


@njit(cache=True, inline="always")
def duration_measure(
    kind: int,
    a: int,
    row: int,
    now: float,
    present: np.ndarray,
    speed: np.ndarray,
    on_net: np.ndarray,
    since: np.ndarray,
) -> float:
    """How long (s) the row's state (standing still / off the road network) has lasted at
    ``now``; ``since[row]`` (NaN: not in the state) is updated."""
    state = speed[a] < STANDSTILL_SPEED if kind == STANDSTILL else not on_net[a]
    if state and present[a]:
        if since[row] != since[row]:
            since[row] = now
    else:
        since[row] = math.nan
    return now - since[row] if present[a] else math.nan


@njit(cache=True, inline="always")
def point_measure(
    kind: int,
    a: int,
    px: float,
    py: float,
    fs: bool,
    centre: np.ndarray,
    ref: np.ndarray,
    cos_h: np.ndarray,
    sin_h: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    speed: np.ndarray,
) -> float:
    """Distance (m), reach distance (m) or TTC (s) of A to the point (``px``, ``py``) (NaN:
    no point, i.e. A absent)."""
    if px != px:
        return math.nan
    dx, dy = px - ref[a, 0], py - ref[a, 1]
    dist = math.hypot(dx, dy)
    if fs and kind != REACH:  # kinematics.rectangle_point_distance
        x, y = _unrotate(px - centre[a, 0], py - centre[a, 1], cos_h[a], sin_h[a])
        dist = _outside(x, y, 0.5 * length[a], 0.5 * width[a])
    if kind == TTC_POINT:
        n = max(math.hypot(dx, dy), 1e-9)
        closing = speed[a] * (cos_h[a] * dx + sin_h[a] * dy) / n
        return dist / max(closing, 1e-9) if closing > 1e-9 else math.inf
    return dist
