"""What entity conditions measure at one step, one condition row at a time, compiled.

A row is one (condition, triggering entity) pair. Rows are compiled into one table
(:class:`EntityRows`) and measured by :mod:`trigger_kernel` in one compiled loop, each row by
the scalar functions here: pair measures (relative distance, headway, TTC to an entity),
single-entity measures (speed, acceleration, relative speed), durations (standstill, end of
road) and point measures (distance, reach, TTC to a position). The geometry is the
kinematics kernel's own scalar functions (:mod:`hiyari.kinematics_scalar`), which
:mod:`hiyari.kinematics`' array functions loop over too.
Rows whose entities are absent measure NaN, which no rule holds for.

Frames and units: world x, y in metres, headings in radians from world +x, speeds m/s, times
s. An entity's ``centre`` is its bounding-box centre, ``ref`` its reference point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.openscenario.engine.kernels.tables import EntityFields
from hiyari.bridge.openscenario.model.positions import LanePosition, RoadPosition, WorldPosition
from hiyari.jit import njit
from hiyari.kinematics_scalar import (
    footprint_distance_cs,
    footprint_extent,
    max0,
    rectangle_point_distance,
    unrotate,
)

#: Speed below which an actor stands still, m/s.
STANDSTILL_SPEED = 0.01
#: Row kinds, by the group that measures them.
REL_DIST, HEADWAY, TTC = 0, 1, 2
SPEED, ACCEL, REL_SPEED = 3, 4, 5
STANDSTILL, END_OF_ROAD = 6, 7
DISTANCE, REACH, TTC_POINT = 8, 9, 10
COLLISION = 11
TRAVELED = 12
#: Kinds tracked every step, whether their trigger is evaluated or not.
DURATION_KINDS = (STANDSTILL, END_OF_ROAD, TRAVELED)
#: The frame a distance is measured in (a row's coordinateSystem): the triggering entity's
#: axes, road / lane coordinates (s, t), the world's x and y axes.
ENTITY_FRAME, ROAD_FRAME, WORLD_FRAME = 0, 1, 2
POINT_KINDS = (DISTANCE, REACH, TTC_POINT)
#: Positions that do not depend on where the entities are: resolved once.
FIXED_POSITIONS = (WorldPosition, LanePosition, RoadPosition)


@njit(cache=True)
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
    1 longitudinal, 2 lateral; a speed's or acceleration's direction, ``DIR_NONE`` ...),
    frame (``ENTITY_FRAME`` ...) and the condition body."""

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


# ---------------------------------------------------------------------------------- entities
#: Fields of an entity's scalars (the tuple :func:`entity_scalars` returns): box centre x, y
#: and reference point x, y (m), heading (rad) with its cos and sin, length and width (m),
#: speed (m/s), acceleration (m/s^2), road s and t (m), road direction (+1 / -1) and road
#: code (ActorTable.road_ids; -1: none).
E_X, E_Y, E_RX, E_RY, E_H, E_COS, E_SIN, E_LEN, E_WID, E_V, E_ACC, E_S, E_T, E_DIR, E_ROAD = range(
    15
)
N_FIELDS = 15


@njit(cache=True)
def pack_entities(ent: EntityFields, out: np.ndarray) -> None:
    """Into ``out`` (E, N_FIELDS): each entity's fields (columns ``E_X`` ...), cos and sin of
    the heading computed here. The measures read their scalars from it: a compiled function
    that is handed many arrays per row pays a reference count per array and call (about 0.1
    microseconds each, more than the measure itself)."""
    centre, ref = ent.centre, ent.ref
    for k in range(len(ent.heading)):
        h = ent.heading[k]
        out[k, E_X], out[k, E_Y], out[k, E_RX], out[k, E_RY] = (
            centre[k, 0], centre[k, 1], ref[k, 0], ref[k, 1]
        )  # fmt: skip
        out[k, E_H], out[k, E_COS], out[k, E_SIN] = h, math.cos(h), math.sin(h)
        out[k, E_LEN], out[k, E_WID], out[k, E_V], out[k, E_ACC] = (
            ent.length[k], ent.width[k], ent.speed[k], ent.accel[k]
        )  # fmt: skip
        out[k, E_S], out[k, E_T], out[k, E_DIR] = ent.road_s[k], ent.road_t[k], ent.road_dir[k]
        out[k, E_ROAD] = ent.road_code[k]


@njit(cache=True)
def entity_scalars(k: int, packed: np.ndarray) -> tuple:
    """Entity ``k``'s fields (see ``E_X`` ...) from :func:`pack_entities`'s array, as one
    tuple of floats."""
    return (
        packed[k, E_X], packed[k, E_Y], packed[k, E_RX], packed[k, E_RY], packed[k, E_H],
        packed[k, E_COS], packed[k, E_SIN], packed[k, E_LEN], packed[k, E_WID],
        packed[k, E_V], packed[k, E_ACC], packed[k, E_S], packed[k, E_T], packed[k, E_DIR],
        packed[k, E_ROAD],
    )  # fmt: skip


# ---------------------------------------------------------------------------------- pairs
@njit(cache=True)
def in_road_of(ea: tuple, eb: tuple, links: np.ndarray) -> tuple:
    """B's fields with its road s, t and direction expressed on A's road (``links``: road
    b's s in road a's frame is shift + sign * s, see ConditionBank.link_roads; a road
    entered at its end turns t and the direction with it): both roads' s then measure along
    the road links. B's road s NaN when the roads are not linked (no rule holds)."""
    ra, rb = int(ea[E_ROAD]), int(eb[E_ROAD])
    if ra == rb or ra < 0 or rb < 0:
        return eb
    shift, sign = math.nan, 1.0
    if ra < links.shape[0] and rb < links.shape[0]:
        shift, sign = links[ra, rb, 0], links[ra, rb, 1]
    return (
        eb[E_X], eb[E_Y], eb[E_RX], eb[E_RY], eb[E_H], eb[E_COS], eb[E_SIN], eb[E_LEN],
        eb[E_WID], eb[E_V], eb[E_ACC], shift + sign * eb[E_S], sign * eb[E_T],
        sign * eb[E_DIR], ea[E_ROAD],
    )  # fmt: skip


@njit(cache=True)
def _entity_distance(fs: bool, dtype: int, ea: tuple, eb: tuple) -> float:
    """Distance (m) of B from A in A's frame, by distance type: between the reference points,
    or the boxes' gap with ``fs`` (freespace)."""
    ha, la, wa, ca, sa = ea[E_H], ea[E_LEN], ea[E_WID], ea[E_COS], ea[E_SIN]
    if dtype == 0 and fs:
        return footprint_distance_cs(
            ea[E_X], ea[E_Y], ha, ca, sa, la, wa,
            eb[E_X], eb[E_Y], eb[E_H], eb[E_COS], eb[E_SIN], eb[E_LEN], eb[E_WID],
        )  # fmt: skip
    if not fs:
        rx, ry = unrotate(eb[E_RX] - ea[E_RX], eb[E_RY] - ea[E_RY], ca, sa)
        return math.hypot(rx, ry) if dtype == 0 else (abs(rx) if dtype == 1 else abs(ry))
    bx, by = unrotate(eb[E_X] - ea[E_X], eb[E_Y] - ea[E_Y], ca, sa)
    ext_x, ext_y = footprint_extent(eb[E_LEN], eb[E_WID], eb[E_H] - ha)  # B in A's frame
    if dtype == 1:
        return max0(abs(bx) - 0.5 * la - ext_x)
    return max0(abs(by) - 0.5 * wa - ext_y)


@njit(cache=True)
def _reference_road(e: tuple) -> tuple[float, float]:
    """Road s, t of an entity's reference point: its box centre's less the centre's offset
    along and across its heading (taken as the road's direction there)."""
    along, left = unrotate(e[E_X] - e[E_RX], e[E_Y] - e[E_RY], e[E_COS], e[E_SIN])
    return e[E_S] - e[E_DIR] * along, e[E_T] - e[E_DIR] * left


@njit(cache=True)
def _road_distance(fs: bool, dtype: int, ea: tuple, eb: tuple) -> float:
    """Distance (m) of B from A in road coordinates, by distance type: between the boxes
    (``fs``: their centres' s, t less half their lengths, widths) or the reference points."""
    if fs:
        ds = (eb[E_S] - ea[E_S]) * ea[E_DIR]
        dt = eb[E_T] - ea[E_T]
        lon = max0(abs(ds) - 0.5 * (ea[E_LEN] + eb[E_LEN]))
        lat = max0(abs(dt) - 0.5 * (ea[E_WID] + eb[E_WID]))
    else:
        sa, ta = _reference_road(ea)
        sb, tb = _reference_road(eb)
        lon, lat = abs(sb - sa), abs(tb - ta)
    if dtype == 1:
        return lon
    if dtype == 2:
        return lat
    return math.hypot(lon, lat)


@njit(cache=True)
def _world_distance(fs: bool, dtype: int, ea: tuple, eb: tuple) -> float:
    """Distance (m) of B from A along the world's x (longitudinal) and y (lateral) axes:
    between the reference points, or with ``fs`` between the boxes' extents along the axes
    (euclidean: the boxes' distance, the same in every frame)."""
    if dtype == 0 and fs:
        return footprint_distance_cs(
            ea[E_X], ea[E_Y], ea[E_H], ea[E_COS], ea[E_SIN], ea[E_LEN], ea[E_WID],
            eb[E_X], eb[E_Y], eb[E_H], eb[E_COS], eb[E_SIN], eb[E_LEN], eb[E_WID],
        )  # fmt: skip
    if fs:
        ax, ay = footprint_extent(ea[E_LEN], ea[E_WID], ea[E_H])
        bx, by = footprint_extent(eb[E_LEN], eb[E_WID], eb[E_H])
        lon = max0(abs(eb[E_X] - ea[E_X]) - ax - bx)
        lat = max0(abs(eb[E_Y] - ea[E_Y]) - ay - by)
    else:
        lon, lat = abs(eb[E_RX] - ea[E_RX]), abs(eb[E_RY] - ea[E_RY])
    return math.hypot(lon, lat) if dtype == 0 else (lon if dtype == 1 else lat)


@njit(cache=True)
def _sign(x: float) -> float:
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return x  # 0 or NaN, as np.sign


@njit(cache=True)
def _closing(dtype: int, ea: tuple, eb: tuple, world: bool = False) -> float:
    """Closing speed (m/s) of A and B along the measuring direction: A's axis (longitudinal /
    lateral; with ``world`` the world's x / y axis) or the line between the centres
    (euclidean)."""
    ca, sa, va, vb = ea[E_COS], ea[E_SIN], ea[E_V], eb[E_V]
    dvx, dvy = va * ca - vb * eb[E_COS], va * sa - vb * eb[E_SIN]  # relative velocity
    rx, ry = eb[E_X] - ea[E_X], eb[E_Y] - ea[E_Y]
    n = max(math.hypot(rx, ry), 1e-9)
    if world and dtype == 1:
        dx, dy = 1.0, 0.0
    elif world and dtype == 2:
        dx, dy = 0.0, 1.0
    elif dtype == 1:
        dx, dy = ca, sa
    elif dtype == 2:
        dx, dy = -sa, ca
    else:
        dx, dy = rx / n, ry / n
    return (dvx * dx + dvy * dy) * _sign(rx * dx + ry * dy)


@njit(cache=True)
def pair_measure(kind: int, fs: bool, dtype: int, frame: int, ea: tuple, eb: tuple) -> float:
    """Relative distance (m), time headway (s) or TTC (s) of present entity A to present
    entity B (their :func:`entity_scalars`) in ``frame``. The distance is measured only when
    the headway or TTC needs it (B ahead and A moving; closing)."""
    closing = 0.0
    road = frame == ROAD_FRAME
    if kind == HEADWAY:
        if road:
            ahead = (eb[E_S] - ea[E_S]) * ea[E_DIR]
        else:  # B's centre along A's axis, as unrotate
            ahead = (eb[E_X] - ea[E_X]) * ea[E_COS] + (eb[E_Y] - ea[E_Y]) * ea[E_SIN]
        if not (ahead > 0 and ea[E_V] > 1e-6):
            return math.inf
    elif kind == TTC:
        closing = _closing(dtype, ea, eb, frame == WORLD_FRAME)
        if not closing > 1e-9:
            return math.inf
    if road:
        dist = _road_distance(fs, dtype, ea, eb)
    elif frame == WORLD_FRAME:
        dist = _world_distance(fs, dtype, ea, eb)
    else:
        dist = _entity_distance(fs, dtype, ea, eb)
    if kind == HEADWAY:
        return dist / max(ea[E_V], 1e-6)
    if kind == TTC:
        return dist / max(closing, 1e-9)
    return dist


@njit(cache=True)
def ttc_above(value: float, ea: tuple, eb: tuple) -> bool:
    """Whether the freespace euclidean TTC of present A to present B (``pair_measure``) is
    certainly infinite (not closing) or above ``value`` (s, below infinity), found without
    the footprint distance: the boxes' gap is at least the centres' distance less both
    half-diagonals (less a micrometre per metre, far above the rounding of either)."""
    closing = _closing(0, ea, eb)
    if not closing > 1e-9:
        return True
    apart = math.hypot(eb[E_X] - ea[E_X], eb[E_Y] - ea[E_Y])
    gap = apart - 0.5 * (math.hypot(ea[E_LEN], ea[E_WID]) + math.hypot(eb[E_LEN], eb[E_WID]))
    margin = 1e-6 * (1.0 + apart)
    return gap - margin > 0.0 and gap - margin > value * closing * (1.0 + 1e-9)


# ---------------------------------------------------------------------------------- one entity
#: The direction of a speed, acceleration or relative-speed row (its distance-type column):
#: none (the speed; the acceleration along the heading; the difference of the speeds), or the
#: triggering entity's longitudinal, lateral or vertical axis (OpenSCENARIO's
#: DirectionalDimension).
DIR_NONE, DIR_LON, DIR_LAT, DIR_VERT = 0, 1, 2, 3


@njit(cache=True)
def single_measure(kind: int, direction: int, ea: tuple, eb: tuple) -> float:
    """Speed (m/s) or acceleration (m/s^2) of present entity A, or its speed relative to
    present entity B (A's minus B's), by ``direction``. A velocity is along its entity's
    heading and in the plane (the WorldState's: speed times the heading's unit vector), so
    an entity's own lateral and vertical speeds are 0 and its relative velocity to B in its
    axes is (v_a - v_b cos(h_b - h_a), -v_b sin(h_b - h_a), 0). The vertical acceleration is
    0 (level entities, planar motion); the lateral one is :func:`lateral_accel_measure`'s.
    With no direction a speed is the velocity's magnitude (the standard's total speed; a
    reversing entity's is positive) and the relative speed the difference of the speeds;
    the total acceleration is :func:`total_accel_measure`'s."""
    if kind == SPEED:  # with no direction the total speed: the velocity's magnitude
        if direction == DIR_NONE:
            return abs(ea[E_V])
        return ea[E_V] if direction == DIR_LON else 0.0
    if kind == ACCEL:
        return ea[E_ACC] if direction <= DIR_LON else 0.0
    if direction == DIR_NONE:
        return ea[E_V] - eb[E_V]
    if direction == DIR_VERT:
        return 0.0
    dh = eb[E_H] - ea[E_H]
    if direction == DIR_LON:
        return ea[E_V] - eb[E_V] * math.cos(dh)
    return -eb[E_V] * math.sin(dh)


@njit(cache=True)
def lateral_accel_measure(
    now: float, present: bool, heading: float, speed: float, last_h: float, last_t: float
) -> tuple[float, float, float]:
    """Lateral acceleration (m/s^2, positive to the left) of an entity at ``now``: its speed
    times its yaw rate, the heading's change (wrapped to (-pi, pi]) since the previous
    evaluation (``last_h`` rad at ``last_t`` s, NaN: none) over the time between; NaN at the
    first evaluation and while absent. Returns it with the heading and time to keep."""
    if not present:
        return math.nan, math.nan, math.nan
    if last_t != last_t or now <= last_t:
        return math.nan, heading, now
    turn = (heading - last_h + math.pi) % (2.0 * math.pi) - math.pi
    return speed * turn / (now - last_t), heading, now


@njit(cache=True)
def total_accel_measure(longitudinal: float, lateral: float) -> float:
    """Total acceleration (m/s^2): the magnitude of the acceleration vector from its
    ``longitudinal`` and ``lateral`` components (planar motion: no vertical one); NaN while
    the lateral one is (:func:`lateral_accel_measure`: the first evaluation)."""
    if lateral != lateral:
        return math.nan
    return math.sqrt(longitudinal * longitudinal + lateral * lateral)


@njit(cache=True)
def duration_measure(
    kind: int, now: float, present: bool, speed: float, on_net: bool, since: float
) -> tuple[float, float]:
    """How long (s) an entity's state (standing still / off the road network) has lasted at
    ``now`` (NaN: absent), and the state's start time (s; NaN: not in the state) to keep,
    given the one kept so far (``since``)."""
    state = speed < STANDSTILL_SPEED if kind == STANDSTILL else not on_net
    if state and present:
        if since != since:
            since = now
    else:
        since = math.nan
    return (now - since if present else math.nan), since


@njit(cache=True)
def traveled_measure(
    now: float, present: bool, speed: float, travelled: float, last: float
) -> tuple[float, float, float]:
    """Metres an entity has travelled by ``now`` (the integral of its speed's magnitude over
    the steps it was present, from its first evaluation), and the distance and time to keep
    (``travelled``, ``last``: kept so far, NaN before the first evaluation)."""
    if travelled != travelled:
        return 0.0, 0.0, now
    if present:
        travelled += abs(speed) * (now - last)
    return travelled, travelled, now


@njit(cache=True)
def point_measure(kind: int, fs: bool, dtype: int, frame: int, ea: tuple, point: tuple) -> float:
    """Distance (m), reach distance (m) or TTC (s) of A to a point: ``point`` its world x, y
    and road s, t (m; x NaN: no point, i.e. A absent; s NaN: off the roads).

    Measured by distance type ``dtype`` (0 euclidean, 1 longitudinal, 2 lateral) in A's frame,
    along the world's x / y axes (``frame`` WORLD_FRAME; with ``fs`` from A's box's extents
    along them) or (ROAD_FRAME) in road coordinates (s, t differences; A's reference point's taken as
    its box centre's less the centre's offset along and across A's heading), between A's
    reference point and the point or, with ``fs``, A's box and the point (a point has no
    extent). The reach distance is always euclidean between the reference point and the
    point. The TTC is the distance over the closing speed along the measuring direction."""
    px, py, ps, pt = point
    if px != px:
        return math.nan
    dx, dy = px - ea[E_RX], py - ea[E_RY]
    fs = fs and kind != REACH
    road, world = frame == ROAD_FRAME, frame == WORLD_FRAME
    if kind == REACH or (dtype == 0 and not road):
        dist = math.hypot(dx, dy)
        if fs:
            dist = rectangle_point_distance(
                ea[E_X], ea[E_Y], ea[E_COS], ea[E_SIN], 0.5 * ea[E_LEN], 0.5 * ea[E_WID], px, py
            )
        if kind != TTC_POINT:
            return dist
        n = max(math.hypot(dx, dy), 1e-9)
        closing = ea[E_V] * (ea[E_COS] * dx + ea[E_SIN] * dy) / n
        return dist / max(closing, 1e-9) if closing > 1e-9 else math.inf
    if road:  # as _road_distance, the point with no extent
        s, t = ea[E_S], ea[E_T]  # of the box centre; the reference point's without freespace
        if not fs:
            s, t = _reference_road(ea)
        lon, lat = abs((ps - s) * ea[E_DIR]), abs(pt - t)
    elif world and fs:  # A's box's extents along the world axes
        ex, ey = footprint_extent(ea[E_LEN], ea[E_WID], ea[E_H])
        lon, lat = max0(abs(px - ea[E_X]) - ex), max0(abs(py - ea[E_Y]) - ey)
    elif world:
        lon, lat = abs(dx), abs(dy)
    elif fs:
        lon, lat = unrotate(px - ea[E_X], py - ea[E_Y], ea[E_COS], ea[E_SIN])
        lon, lat = abs(lon), abs(lat)
    else:
        lon, lat = unrotate(dx, dy, ea[E_COS], ea[E_SIN])
        lon, lat = abs(lon), abs(lat)
    if fs and not world:
        lon, lat = max0(lon - 0.5 * ea[E_LEN]), max0(lat - 0.5 * ea[E_WID])
    dist = lon if dtype == 1 else (lat if dtype == 2 else math.hypot(lon, lat))
    if kind != TTC_POINT:
        return dist
    # closing speed along A's axis (longitudinal, lateral) or towards the point (euclidean),
    # as _closing with the point standing still
    ca, sa, v = ea[E_COS], ea[E_SIN], ea[E_V]
    if world and dtype != 0:
        ux, uy = (1.0, 0.0) if dtype == 1 else (0.0, 1.0)
    elif dtype == 1:
        ux, uy = ca, sa
    elif dtype == 2:
        ux, uy = -sa, ca
    else:
        n = max(math.hypot(dx, dy), 1e-9)
        ux, uy = dx / n, dy / n
    closing = v * (ca * ux + sa * uy) * _sign(dx * ux + dy * uy)
    return dist / max(closing, 1e-9) if closing > 1e-9 else math.inf
