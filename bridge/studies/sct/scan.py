"""The SCT study's per-step scan, compiled: who is near a junction, and which pairs need work.

Every stepped step of an arm asks which vehicles are within the vehicle zone of a junction
with crossings and which pedestrians within the pedestrian zone, and, for those pairs, lower
bounds on when they could touch (contact_kernel.pair_time_bounds): the pairs to log, whether
the controller must plan, and how long nothing can happen. In numpy that is some twenty small
array operations per step; here it is one call with the same operations per scalar, so the
study's decisions are unchanged (tests/unit/risk/test_sct_contact_kernel.py).

Frames and units: network coordinates in metres, speeds m/s, times s.
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.jit import njit
from hiyari.risk.sct.contact_kernel import pair_time_bounds


@njit(cache=True)
def zone_scan(
    xy: np.ndarray,
    is_ped: np.ndarray,
    centres: np.ndarray,
    vehicle_zone2: float,
    pedestrian_zone2: float,
    length: np.ndarray,
    width: np.ndarray,
    margin: float,
    radius: float,
    speed: np.ndarray,
    ped_speed: float,
    accel: float,
    log_horizon: float,
    plan_horizon: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool, float]:
    """Actors at ``xy`` (N, 2) (``is_ped`` (N,)), junction ``centres`` (J, 2): squared
    distance to the nearest junction (N,); rows of vehicles within sqrt(``vehicle_zone2``)
    and of pedestrians within sqrt(``pedestrian_zone2``); of their pairs, the (vehicle,
    pedestrian) rows that could touch within ``log_horizon`` s at current speeds (row-major
    over the zone's vehicles, then pedestrians), whether some pair could touch within
    ``plan_horizon`` s with the vehicle accelerating at ``accel`` m/s^2, and the least such
    bound (s, inf without pairs). Vehicles: sizes (N,) m grown by ``margin`` (circumscribed
    circle), ``speed`` (N,) m/s; pedestrians: discs of ``radius`` m at most ``ped_speed``
    m/s."""
    n = len(xy)
    d2 = np.empty(n)
    for i in range(n):
        low = np.inf
        for j in range(len(centres)):
            dx = xy[i, 0] - centres[j, 0]
            dy = xy[i, 1] - centres[j, 1]
            low = min(low, dx * dx + dy * dy)
        d2[i] = low
    vin = np.flatnonzero(~is_ped & (d2 <= vehicle_zone2))
    pin = np.flatnonzero(is_ped & (d2 <= pedestrian_zone2))
    if len(vin) == 0 or len(pin) == 0:
        empty = np.zeros(0, np.int64)
        return d2, vin, pin, empty, empty, False, np.inf
    vxy = np.empty((len(vin), 2))
    reach = np.empty(len(vin))
    for a in range(len(vin)):
        r = vin[a]
        vxy[a, 0], vxy[a, 1] = xy[r, 0], xy[r, 1]
        reach[a] = 0.5 * math.hypot(length[r], width[r]) + margin
    pxy = np.empty((len(pin), 2))
    for b in range(len(pin)):
        pxy[b, 0], pxy[b, 1] = xy[pin[b], 0], xy[pin[b], 1]
    tau_now, tau_acc = pair_time_bounds(vxy, pxy, reach, radius, speed[vin], ped_speed, accel)
    vi, pj = np.nonzero(tau_now <= log_horizon)
    return d2, vin, pin, vin[vi], pin[pj], (tau_acc <= plan_horizon).any(), tau_acc.min()
