"""The pedestrians' predictions of one step in one compiled pass (SCTModel.prepare).

Every evaluated step predicts each pedestrian's velocity (constant, or the dart-out step into
the carriageway), its track under every speed hypothesis over the horizon, its
constant-velocity track (time to contact), and which track points lie on the carriageway. In
numpy that is some thirty small array operations per step; here it is one call running
contact._predict, the operations of contact.pedestrian_tracks and of the pair metrics'
constant-velocity tracks per scalar in the same order, and area_kernel.locate_xy, so every
value is the numpy / shapely one bit for bit (tests/e2e/risk/test_sct_track_kernel.py). The facing test
(a matrix product) and the headings' cosine / sine stay numpy's and come in as arguments.
row_slots gives the step view's row-to-slot maps in the same spirit.

Frames and units: network coordinates in metres, speeds m/s, times s.
"""

from __future__ import annotations

import numpy as np

from hiyari.jit import njit
from hiyari.risk.metrics.contact import _predict
from hiyari.risk.sct.area_kernel import locate_xy

#: ``area`` of predict_tracks: where pedestrians are exposed to vehicles.
EVERYWHERE = 0  # no carriageway: every point
RINGS = 1  # inside the rings, counted in locate_xy (GEOS settles the undecided points)
ASK_ALL = -1  # an area locate_xy cannot count: GEOS answers every point


@njit(cache=True)
def predict_tracks(
    xyz: np.ndarray,
    state_speed: np.ndarray,
    ped: np.ndarray,
    u: np.ndarray,
    predict: bool,
    rows: np.ndarray,
    facing: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    inward: np.ndarray,
    crossing: np.ndarray,
    open_crossings: np.ndarray,
    cos_max: float,
    reach: float,
    dart_speed: float,
    factors: np.ndarray,
    times: np.ndarray,
    area: int,
    ring_xy: np.ndarray,
    ring_start: np.ndarray,
    slab_y: np.ndarray,
    slab_start: np.ndarray,
    slab_edges: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The predictions of P pedestrians, rows ``ped`` of a state's columns ``xyz`` (N, 3) m
    and ``state_speed`` (N,) m/s, heading along ``u`` (P, 2), at the K ``times`` s.

    Returns, with ``predict`` (else NaN velocities, no dart-out and no tracks, P' = 0):
    velocities (P, 2) m/s and dart-out flags (P,) (contact._predict, its other arguments
    describing the kerbs (K,), possibly none) and their tracks (P', H, K, 2) m at the H speed
    ``factors`` (contact.pedestrian_tracks); always the constant-velocity tracks (P, K, 2) m
    at their own speed (pair_kernel's, whose first point is ``xy`` itself). Then whether each
    point of both is on the carriageway ((P', H, K) and (P, K) bool), and the indices of the
    points whose answer GEOS must give, into the tracks' points followed by the
    constant-velocity points (``area``: EVERYWHERE, RINGS with the carriageway's rings and
    slabs, or ASK_ALL)."""
    n_p, n_h, n_k = len(ped), len(factors), len(times)
    xy = np.empty((n_p, 2))
    speed = np.empty(n_p)
    for p in range(n_p):
        xy[p, 0], xy[p, 1], speed[p] = xyz[ped[p], 0], xyz[ped[p], 1], state_speed[ped[p]]
    if predict:
        vel, dart = _predict(
            xy, u, speed, rows, facing, a, b, inward, crossing, open_crossings, cos_max,
            reach, dart_speed,
        )  # fmt: skip
    else:
        vel, dart = np.full((n_p, 2), np.nan), np.zeros(n_p, np.bool_)
    n_t = n_p if predict else 0
    # one buffer for both sets of points: one locate_xy call
    points = np.empty((n_t * n_h * n_k + n_p * n_k, 2))
    tracks = points[: n_t * n_h * n_k].reshape(n_t, n_h, n_k, 2)
    cv = points[n_t * n_h * n_k :].reshape(n_p, n_k, 2)
    for p in range(n_t):
        for h in range(n_h):
            vx = vel[p, 0] * factors[h]
            vy = vel[p, 1] * factors[h]
            for k in range(n_k):
                tracks[p, h, k, 0] = xy[p, 0] + vx * times[k]
                tracks[p, h, k, 1] = xy[p, 1] + vy * times[k]
    for p in range(n_p):
        vx = u[p, 0] * speed[p]
        vy = u[p, 1] * speed[p]
        for k in range(n_k):
            cv[p, k, 0] = xy[p, 0] + vx * times[k]
            cv[p, k, 1] = xy[p, 1] + vy * times[k]
    n = len(points)
    if area == EVERYWHERE:
        on = np.ones(n, np.bool_)
        ask = np.zeros(0, np.int64)
    elif area == ASK_ALL:
        on = np.zeros(n, np.bool_)
        ask = np.arange(n)
    else:
        where = locate_xy(points, ring_xy, ring_start, slab_y, slab_start, slab_edges)
        on = where == 1
        ask = np.flatnonzero(where < 0)
    exposed = on[: n_t * n_h * n_k].reshape(n_t, n_h, n_k)
    cv_exposed = on[n_t * n_h * n_k :].reshape(n_p, n_k)
    return vel, dart, tracks, cv, exposed, cv_exposed, ask


@njit(cache=True)
def row_slots(n: int, veh: np.ndarray, ped: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N,) each of ``n`` state rows' index into the vehicle rows ``veh`` and into the
    pedestrian rows ``ped`` (-1: not among them)."""
    veh_slot = np.full(n, -1, np.int64)
    ped_slot = np.full(n, -1, np.int64)
    for i in range(len(veh)):
        veh_slot[veh[i]] = i
    for i in range(len(ped)):
        ped_slot[ped[i]] = i
    return veh_slot, ped_slot
