"""One compiled pass per step over the scripted actors on roads: the running longitudinal and
lateral transitions (stored as rows of parameters in the ActorTable) and the integration of
s, t and v.

Longitudinal: the speed goes from ``v0`` to the goal with the transition's shape over its
span (seconds, or metres travelled); within the step the actor ramps linearly from the old to
the new speed (up to the transition's end when it ended inside the step): the distance ``d``
it travels in the step. Lateral: t goes from ``t0`` to the target lane's centre line (from the
LaneProfile, at the new s) plus an offset, ``dt_lat`` in the step.

The speed is the speed along the actor's path (OpenSCENARIO's speed of an entity; a lane
change or lane offset does not make it faster): in the road's frame at the actor's offset t,
the step's displacement is (``d_lane``, ``dt_lat``) with ``d_lane² + dt_lat² = d²``, so the
distance along the lane is ``d_lane = sqrt(d² - dt_lat²)`` (0 when the lateral motion alone
is longer than ``d``: the actor then moves sideways, faster than its speed), and s advances by
``d_lane / (1 - curvature * t)``. The lane centre is evaluated at s advanced by ``d`` (the
lateral transition is solved before the correction: a lane's width changes by far less than
a millimetre over the difference). The heading slips by ``atan2(dt_lat, d_lane)``, the
direction of that displacement. Units: s, t in metres, v in m/s, times in seconds of scenario
time.
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.bridge.openscenario.engine.kernels.shapes import shape_progress
from hiyari.bridge.openscenario.engine.kernels.tables import (
    ActorArrays,
    LaneArrays,
    RoadArrays,
)
from hiyari.jit import njit
from hiyari.net.road.lane_profile import lane_centre_at
from hiyari.net.road.plan_view import road_pose_at

#: The ActorTable's float columns, rows of its ``state`` matrix (one column per actor): road
#: s and t (m), speed (m/s), acceleration (m/s^2), lateral speed (m/s), heading relative to
#: the lane (rad), world x, y, z (m) and heading (rad), metres travelled since the running
#: longitudinal / lateral transition started. One matrix: a kernel takes one argument for
#: all (numba's dispatch costs about as much per argument as the kernel's work per actor).
#: ``step_travelled``: the distance along the path in the latest step (the lateral pass takes
#: its lateral share out of the distance along the lane).
STATE = ("s", "t", "v", "accel", "v_lat", "h_rel", "x", "y", "z", "h",
         "long_travelled", "lat_travelled", "step_travelled")  # fmt: skip
S, T, V, ACCEL, V_LAT, H_REL, X, Y, Z, H, LONG_TRAV, LAT_TRAV, STEP_TRAV = range(len(STATE))
#: Columns of the longitudinal parameter rows: start speed (m/s), goal speed (m/s; refreshed
#: each step for targets that follow another entity), shape code, span (s or m), by distance
#: (0 / 1), continuous (0 / 1), start time (s), goal reached (0 / 1).
L_V0, L_GOAL, L_SHAPE, L_SPAN, L_BY_DIST, L_CONT, L_T0, L_REACHED = range(8)
#: Columns of the lateral parameter rows: start t (m), offset from the target lane's centre
#: (m; refreshed for continuous relative offsets), shape code, span (s or m), by distance,
#: continuous, start time (s), target lane id, road index in the table's LaneProfile.
T_T0, T_OFFSET, T_SHAPE, T_SPAN, T_BY_DIST, T_CONT, T_START, T_LANE, T_ROAD = range(9)
#: Progress at or beyond which a transition has arrived.
_ARRIVED = 1.0 - 1e-9


@njit(cache=True)
def _speed(p: np.ndarray, now: float, travelled: float) -> tuple[float, bool]:
    """(speed at ``now``, done) of longitudinal parameter row ``p`` after ``travelled`` m."""
    goal, span = p[L_GOAL], p[L_SPAN]
    if span <= 0:
        x = 1.0
    else:
        x = (travelled if p[L_BY_DIST] != 0.0 else now - p[L_T0]) / span
    if p[L_REACHED] != 0.0 or x >= _ARRIVED:
        p[L_REACHED] = 1.0
        return goal, p[L_CONT] == 0.0
    return p[L_V0] + (goal - p[L_V0]) * shape_progress(int(p[L_SHAPE]), x), False


@njit(cache=True)
def _lateral(p: np.ndarray, goal: float, now: float, travelled: float) -> tuple[float, bool]:
    """(t at ``now``, done) of lateral parameter row ``p`` towards ``goal`` (m)."""
    span = p[T_SPAN]
    if span <= 0:
        x = 1.0
    else:
        x = (travelled if p[T_BY_DIST] != 0.0 else now - p[T_START]) / span
    if x >= _ARRIVED:
        return goal, p[T_CONT] == 0.0
    return p[T_T0] + (goal - p[T_T0]) * shape_progress(int(p[T_SHAPE]), x), False


@njit(cache=True)
def advance_long(rows: np.ndarray, now: float, dt: float, actors: ActorArrays) -> int:
    """Speeds and s of table ``rows`` one step of ``dt`` s on, at scenario time ``now``
    (``actors.kappa``: reference-line curvature at each row's s before the step); lateral
    speeds reset to 0. Marks ``long_done`` for the transitions that ended and returns their
    number."""
    actors = ActorArrays(*actors)
    st, kappa, direction, long_done = actors.state, actors.kappa, actors.direction, actors.long_done
    n_done = 0
    for i in range(len(rows)):
        k = rows[i]
        v_old = st[V, k]
        v_new = v_old
        ramp = dt  # s of this step spent ramping from v_old to v_new
        long_done[k] = False
        if actors.has_long[k]:
            p = actors.long_par[k]
            v_new, done = _speed(p, now, st[LONG_TRAV, k] + v_old * dt)
            if done:
                long_done[k] = True
                n_done += 1
                if p[L_BY_DIST] == 0.0:  # ended within the step: at v_new since then
                    ramp = min(dt, max(0.0, p[L_T0] + p[L_SPAN] - (now - dt)))
        ds_path = 0.5 * (v_old + v_new) * ramp + v_new * (dt - ramp)
        st[S, k] = st[S, k] + direction[k] * ds_path / max(1e-3, 1.0 - kappa[k] * st[T, k])
        st[V, k] = v_new
        st[ACCEL, k] = (v_new - v_old) / dt
        st[LONG_TRAV, k] += ds_path
        st[LAT_TRAV, k] += ds_path
        st[STEP_TRAV, k] = ds_path
        st[V_LAT, k] = 0.0
    return n_done


@njit(cache=True)
def advance_lat(
    rows: np.ndarray, now: float, dt: float, actors: ActorArrays, lanes: LaneArrays
) -> tuple[int, int]:
    """Lateral positions (and speeds) of table ``rows`` with a running lateral transition at
    scenario time ``now``, towards their target lane's centre at their (new) s plus the
    offset (``lanes``: the lane profile of the table's roads); s takes the lateral share of
    the step's distance back (see the module: the speed is along the path; curvature and
    direction as :func:`advance_long`'s). Marks ``lat_done`` for the transitions that ended.
    Returns (the first row whose target lane is missing at its s or -1, the number ended)."""
    actors, lanes = ActorArrays(*actors), LaneArrays(*lanes)
    st, kappa, direction, lat_done = actors.state, actors.kappa, actors.direction, actors.lat_done
    missing, n_done = -1, 0
    for i in range(len(rows)):
        k = rows[i]
        lat_done[k] = False
        if not actors.has_lat[k]:
            continue
        p = actors.lat_par[k]
        centre, _, bad = lane_centre_at(
            lanes.rec_s0, lanes.rec_c, lanes.off_first, lanes.off_count, lanes.sec_first,
            lanes.sec_count, lanes.sec_s0, lanes.w_first, lanes.w_count, lanes.max_lane,
            int(p[T_ROAD]), int(p[T_LANE]), st[S, k],
        )  # fmt: skip
        if bad >= 0:
            if missing < 0:
                missing = k
            continue
        t_new, done = _lateral(p, centre + p[T_OFFSET], now, st[LAT_TRAV, k])
        d_lat, d = t_new - st[T, k], st[STEP_TRAV, k]
        if d_lat != 0.0 and d != 0.0:
            d_lane = math.sqrt(max(0.0, d * d - d_lat * d_lat))
            back = math.copysign(abs(d) - d_lane, d)  # advance_long moved s by all of d
            st[S, k] -= direction[k] * back / max(1e-3, 1.0 - kappa[k] * st[T, k])
        st[V_LAT, k] = d_lat / dt
        st[T, k] = t_new
        lat_done[k] = done
        n_done += done
    return missing, n_done


@njit(cache=True)
def advance_and_place(
    rows: np.ndarray,
    now: float,
    dt: float,
    lateral: bool,
    actors: ActorArrays,
    lanes: LaneArrays,
    road: RoadArrays,
) -> tuple[int, int, int, bool]:
    """One call for a step of table ``rows`` all on ``road``: :func:`advance_long`, then
    (``lateral``: some row has a lateral transition) :func:`advance_lat`, then
    :func:`place_rows`, unless a lateral transition ended or missed its lane (the caller then
    puts the rows on their lanes and places them). Returns (longitudinal transitions ended,
    first row whose target lane is missing or -1, lateral transitions ended, placed)."""
    n_long = advance_long(rows, now, dt, actors)
    missing, n_lat = -1, 0
    if lateral:
        missing, n_lat = advance_lat(rows, now, dt, actors, lanes)
    if missing >= 0 or n_lat > 0:
        return n_long, missing, n_lat, False
    place_rows(rows, road, actors)
    return n_long, missing, n_lat, True


@njit(cache=True)
def _remainder(a: float, b: float) -> float:
    """numpy's float remainder (the sign of ``b``), as ``np.remainder`` computes it."""
    mod = np.fmod(a, b)
    if mod != 0.0:
        if (b < 0) != (mod < 0):
            mod += b
    else:
        mod = math.copysign(0.0, b)
    return mod


@njit(cache=True)
def _set_pose(
    k: int,
    px: float,
    py: float,
    pz: float,
    h_ref: float,
    direction: np.ndarray,
    st: np.ndarray,
) -> None:
    """World pose of row ``k`` at road point (``px``, ``py``, ``pz``) where the reference line
    heads ``h_ref``: the lane's driving direction, the slip of the lateral motion and the
    heading relative to the lane, wrapped into [-pi, pi)."""
    v = st[V, k]
    slip = 0.0
    if abs(v) > 1e-6:
        lat = direction[k] * st[V_LAT, k]
        if lat == 0.0 and v > 0:
            # atan2(+-0, v > 0) is +-0 exactly (C99 F.9.4.4): saves the call when not sliding
            slip = math.copysign(0.0, lat)
        else:  # the speed is along the path: the lane's share is what the lateral leaves
            along = math.copysign(math.sqrt(max(0.0, v * v - lat * lat)), v)
            slip = math.atan2(lat, along)
    hh = h_ref + (0.0 if direction[k] > 0 else math.pi) + slip + st[H_REL, k]
    st[X, k], st[Y, k], st[Z, k] = px, py, pz
    st[H, k] = _remainder(hh + math.pi, 2 * math.pi) - math.pi


@njit(cache=True)
def place_rows(rows: np.ndarray, road: RoadArrays, actors: ActorArrays) -> None:
    """World poses (x, y, z, heading) of table ``rows`` from their road coordinates on
    ``road``."""
    road, actors = RoadArrays(*road), ActorArrays(*actors)
    st = actors.state
    for i in range(len(rows)):
        k = rows[i]
        px, py, pz, h_ref = road_pose_at(
            road.length, road.geom, road.elev_s0, road.elev_c, st[S, k], st[T, k]
        )
        _set_pose(k, px, py, pz, h_ref, actors.direction, st)


@njit(cache=True)
def place_posed(
    rows: np.ndarray,
    px: np.ndarray,
    py: np.ndarray,
    pz: np.ndarray,
    h_ref: np.ndarray,
    actors: ActorArrays,
) -> None:
    """As :func:`place_rows` from road points and reference headings already evaluated (one
    per row of ``rows``)."""
    actors = ActorArrays(*actors)
    for i in range(len(rows)):
        _set_pose(rows[i], px[i], py[i], pz[i], h_ref[i], actors.direction, actors.state)
