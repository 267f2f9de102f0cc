"""What entity conditions measure at one step, for many condition rows at once.

A row is one (condition, triggering entity) pair. Rows are compiled into one table
(:class:`EntityRows`) and measured by group, each group in one vectorised pass over the rows
being evaluated: pair measures (relative distance, headway, TTC to an entity) share one pass of
the pair geometry, single-entity measures (speed, acceleration, relative speed) another, and
durations (standstill, end of road) a third. Geometry comes from the kinematics kernel. Rows
whose entities are absent measure NaN, which no rule holds for.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.scenario.engine.positions import Pose
from hiyari.bridge.scenario.model.positions import LanePosition, RoadPosition, WorldPosition
from hiyari.kinematics import (
    footprint_distance,
    footprint_extent,
    heading_vector,
    rectangle_point_distance,
    unrotate_xy,
)

#: Speed below which an actor stands still, m/s.
STANDSTILL_SPEED = 0.01
#: Row kinds, by the group that measures them.
REL_DIST, HEADWAY, TTC = 0, 1, 2
SPEED, ACCEL, REL_SPEED = 3, 4, 5
STANDSTILL, END_OF_ROAD = 6, 7
DISTANCE, REACH, TTC_POINT = 8, 9, 10
COLLISION = 11
PAIR_KINDS = (REL_DIST, HEADWAY, TTC)
SINGLE_KINDS = (SPEED, ACCEL, REL_SPEED)
DURATION_KINDS = (STANDSTILL, END_OF_ROAD)
POINT_KINDS = (DISTANCE, REACH, TTC_POINT)
#: Positions that do not depend on where the entities are: resolved once.
FIXED_POSITIONS = (WorldPosition, LanePosition, RoadPosition)

_OPS = (np.greater, np.less, np.equal, np.greater_equal, np.less_equal, np.not_equal)
# per rule code (order of _OPS): holds when measured is [less, equal, greater] than the value
_TRUTH = np.array(
    [[0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 1, 1], [1, 1, 0], [1, 0, 1]], dtype=bool
)  # fmt: skip


def compare(measured: np.ndarray, value: np.ndarray, rule: np.ndarray) -> np.ndarray:
    """Apply rule codes (indices into Rule) elementwise; NaN measures are False."""
    if not len(rule):
        return np.zeros(0, dtype=bool)
    first = int(rule[0])
    if (rule == first).all():
        out = _OPS[first](measured, value)
    else:  # one table lookup for any mix of rules
        out = _TRUTH[rule, 2 * (measured > value) + (measured == value)]
    return out & ~np.isnan(measured)


@dataclass
class Snapshot:
    """What conditions read at one step: per entity (index in the scenario's entity order)
    the reference point, box centre, heading (rad), sizes (m), speed (m/s), acceleration,
    presence, road coordinates of the box centre, and the contacts (entity index pairs)."""

    time: float
    present: np.ndarray  # (E,) bool
    ref: np.ndarray  # (E, 2)
    centre: np.ndarray  # (E, 2)
    heading: np.ndarray
    length: np.ndarray
    width: np.ndarray
    speed: np.ndarray
    accel: np.ndarray
    on_net: np.ndarray  # (E,) bool: on a SUMO lane
    road_s: np.ndarray  # (E,) s of the box centre (nan: unknown)
    road_t: np.ndarray
    road_dir: np.ndarray  # (E,) +1 / -1 driving direction along s
    contacts: set[frozenset[int]]
    contact_any: np.ndarray  # (E,) bool


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


def _present(snap: Snapshot, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return snap.present[a] & (b >= 0) & snap.present[np.maximum(b, 0)]


# ---------------------------------------------------------------------------------- pairs
def pair_measures(snap: Snapshot, rows: EntityRows, sel: np.ndarray) -> np.ndarray:
    """Relative distance (m), time headway (s) or TTC (s) of rows ``sel`` (pair kinds)."""
    a, b = rows.a[sel], np.maximum(rows.b[sel], 0)
    kind, dtype = rows.kind[sel], rows.dtype[sel]
    dist, ahead = _distance(snap, a, b, rows.freespace[sel], dtype, rows.road[sel])
    out = dist
    headway = kind == HEADWAY
    if headway.any():
        v = snap.speed[a]
        thw = np.where((ahead > 0) & (v > 1e-6), dist / np.maximum(v, 1e-6), np.inf)
        out = np.where(headway, thw, out)
    ttc = kind == TTC
    if ttc.any():
        out = np.where(ttc, _ttc(snap, a, b, dtype, dist), out)
    return np.where(_present(snap, a, rows.b[sel]), out, np.nan)


def _distance(
    snap: Snapshot,
    a: np.ndarray,
    b: np.ndarray,
    fs: np.ndarray,
    dtype: np.ndarray,
    road: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(distance, position of B ahead of A along A's axis or the road) per row, by distance
    type, freespace and coordinate system. Only the measures some row needs are computed."""
    ent = np.full(len(a), np.nan)
    ahead = np.full(len(a), np.nan)
    ent_rows = ~road
    if ent_rows.any():
        ha, la, wa = snap.heading[a], snap.length[a], snap.width[a]
        d = snap.centre[b] - snap.centre[a]
        bx, by = unrotate_xy(d[:, 0], d[:, 1], ha)  # B's centre in A's frame
        ext_x, ext_y = footprint_extent(snap.length[b], snap.width[b], snap.heading[b] - ha)
        r = snap.ref[b] - snap.ref[a]
        rx, ry = unrotate_xy(r[:, 0], r[:, 1], ha)
        lon = np.where(fs, np.maximum(0.0, np.abs(bx) - 0.5 * la - ext_x), np.abs(rx))
        lat = np.where(fs, np.maximum(0.0, np.abs(by) - 0.5 * wa - ext_y), np.abs(ry))
        eu = np.hypot(rx, ry)
        box = ent_rows & fs & (dtype == 0)
        if box.any():
            ia, ib = a[box], b[box]
            eu[box] = footprint_distance(
                snap.centre[ia], snap.heading[ia], snap.length[ia], snap.width[ia],
                snap.centre[ib], snap.heading[ib], snap.length[ib], snap.width[ib],
            )  # fmt: skip
        ent = np.where(dtype == 1, lon, np.where(dtype == 2, lat, eu))
        ahead = bx
    if road.any():
        ds = (snap.road_s[b] - snap.road_s[a]) * snap.road_dir[a]
        dt_ = snap.road_t[b] - snap.road_t[a]
        lon = np.where(
            fs, np.maximum(0.0, np.abs(ds) - 0.5 * (snap.length[a] + snap.length[b])), np.abs(ds)
        )
        lat = np.where(
            fs, np.maximum(0.0, np.abs(dt_) - 0.5 * (snap.width[a] + snap.width[b])), np.abs(dt_)
        )
        rd = np.where(dtype == 1, lon, np.where(dtype == 2, lat, np.hypot(lon, lat)))
        ent = np.where(road, rd, ent)
        ahead = np.where(road, ds, ahead)
    return ent, ahead


def _ttc(
    snap: Snapshot, a: np.ndarray, b: np.ndarray, dtype: np.ndarray, dist: np.ndarray
) -> np.ndarray:
    """Time (s) to close ``dist`` at the closing speed along the measuring direction: A's
    axis (longitudinal / lateral) or the line between the centres (euclidean)."""
    ha, hb = snap.heading[a], snap.heading[b]
    ca, sa, va, vb = np.cos(ha), np.sin(ha), snap.speed[a], snap.speed[b]
    dvx, dvy = va * ca - vb * np.cos(hb), va * sa - vb * np.sin(hb)  # relative velocity
    rel = snap.centre[b] - snap.centre[a]
    rx, ry = rel[:, 0], rel[:, 1]
    n = np.maximum(np.hypot(rx, ry), 1e-9)
    dx = np.where(dtype == 1, ca, np.where(dtype == 2, -sa, rx / n))
    dy = np.where(dtype == 1, sa, np.where(dtype == 2, ca, ry / n))
    closing = (dvx * dx + dvy * dy) * np.sign(rx * dx + ry * dy)
    return np.where(closing > 1e-9, dist / np.maximum(closing, 1e-9), np.inf)


# ---------------------------------------------------------------------------------- one entity
def single_measures(snap: Snapshot, rows: EntityRows, sel: np.ndarray) -> np.ndarray:
    """Speed (m/s), acceleration (m/s^2) or speed relative to entity B of rows ``sel``."""
    a, b, kind = rows.a[sel], rows.b[sel], rows.kind[sel]
    rel = kind == REL_SPEED
    m = np.where(kind == SPEED, snap.speed[a], snap.accel[a])
    ok = snap.present[a]
    if rel.any():
        m = np.where(rel, snap.speed[a] - snap.speed[np.maximum(b, 0)], m)
        ok = np.where(rel, _present(snap, a, b), ok)
    return np.where(ok, m, np.nan)


def duration_measures(
    snap: Snapshot, rows: EntityRows, sel: np.ndarray, since: np.ndarray
) -> np.ndarray:
    """How long (s) the row's state (standing still / off the road network) has lasted;
    ``since`` (per row, NaN: not in the state) is updated."""
    a = rows.a[sel]
    state = np.where(
        rows.kind[sel] == STANDSTILL, snap.speed[a] < STANDSTILL_SPEED, ~snap.on_net[a]
    )
    s0 = since[sel]
    s0 = np.where(state & snap.present[a], np.where(np.isnan(s0), snap.time, s0), np.nan)
    since[sel] = s0
    return np.where(snap.present[a], snap.time - s0, np.nan)


def point_measures(
    snap: Snapshot,
    rows: EntityRows,
    sel: np.ndarray,
    resolve: Callable[[object], Pose],
    fixed: dict[int, tuple[float, float]],
) -> np.ndarray:
    """Distance (m), reach distance (m) or TTC (s) of rows ``sel`` to their positions.

    Positions are resolved per row (they may be relative to entities); fixed ones once, kept
    in ``fixed`` by row."""
    a = rows.a[sel]
    pts = np.full((len(sel), 2), np.nan)
    for k, (row, i) in enumerate(zip(sel.tolist(), a.tolist(), strict=True)):
        if not snap.present[i]:
            continue
        xy = fixed.get(row)
        if xy is None:
            pos = rows.body[row].position
            p = resolve(pos)
            xy = (p.x, p.y)
            if isinstance(pos, FIXED_POSITIONS):
                fixed[row] = xy
        pts[k] = xy
    kind = rows.kind[sel]
    d = pts - snap.ref[a]
    dist = np.hypot(d[:, 0], d[:, 1])
    box = rows.freespace[sel] & (kind != REACH)
    if box.any():
        ia = a[box]
        dist[box] = rectangle_point_distance(
            snap.centre[ia], snap.heading[ia], 0.5 * snap.length[ia], 0.5 * snap.width[ia],
            pts[box],
        )  # fmt: skip
    ttc = kind == TTC_POINT
    if ttc.any():
        u = heading_vector(snap.heading[a])
        n = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)
        closing = snap.speed[a] * (u[:, 0] * d[:, 0] + u[:, 1] * d[:, 1]) / n
        dist = np.where(
            ttc, np.where(closing > 1e-9, dist / np.maximum(closing, 1e-9), np.inf), dist
        )
    return np.where(np.isnan(pts[:, 0]), np.nan, dist)  # absent entities: NaN, not inf


def collision_hits(snap: Snapshot, rows: EntityRows, sel: np.ndarray) -> np.ndarray:
    """Whether row ``a`` touches entity ``b`` (or anything when ``b`` is -1) now."""
    out = np.zeros(len(sel), dtype=bool)
    if not snap.contacts and not snap.contact_any.any():
        return out
    for k, (i, j) in enumerate(zip(rows.a[sel].tolist(), rows.b[sel].tolist(), strict=True)):
        out[k] = frozenset((i, j)) in snap.contacts if j >= 0 else bool(snap.contact_any[i])
    return out
