"""Exact time series of the Annex G scenarios, for scripting the other vehicles in SUMO.

Annex G attachment 3 fixes the other vehicles' behaviour so that every tool sees the same
disturbance: a point mass whose lateral velocity is a step from 0 to Vy, whose longitudinal
speed stays at Vo0, whose deceleration is a step (infinite jerk), and whose heading follows
its velocity vector; the lateral motion ends when it is centred in its target lane.

Frame (see :mod:`hiyari.risk.cc.model`): x along the road (m), 0 = the ego's front at t = 0;
y lateral (m, left positive), 0 = the ego lane centre, +lane_width_m = the lane to its left
(SUMO lane index 1 when the ego lane is index 0). ``side=-1`` mirrors a scenario to the
right-hand lane. Positions are front bumpers (SUMO's vehicle position) and lateral centres;
heading in rad counter-clockwise from +x. t = 0 when the manoeuvre starts.

Each scenario also gives ``cc_ego``: the C&C driver's own response (its reference motion in
the ego lane), for comparing an automated system's run with the reference.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiyari.errors import HiyariError
from hiyari.risk.cc.evaluator import (
    ScenarioSetup,
    cut_in_setup,
    cut_out_setup,
    decel_setup,
    ego_response,
)
from hiyari.risk.cc.kinematics import Motion
from hiyari.risk.cc.model import CCParams

_DEFAULT = CCParams()


@dataclass(frozen=True)
class Track:
    """One vehicle's motion sampled at ``t_s`` (s), arrays of the same length.

    ``x_front_m``: front bumper along the road (m); ``y_m``: lateral centre (m);
    ``vx_mps``, ``vy_mps``: velocity (m/s); ``ax_mps2``: longitudinal acceleration (m/s²);
    ``heading_rad``: along the velocity (0 when stopped); ``length_m``, ``width_m``: size.
    """

    name: str
    t_s: np.ndarray
    x_front_m: np.ndarray
    y_m: np.ndarray
    vx_mps: np.ndarray
    vy_mps: np.ndarray
    ax_mps2: np.ndarray
    heading_rad: np.ndarray
    length_m: float
    width_m: float

    @property
    def speed_mps(self) -> np.ndarray:
        """Speed along the path (m/s)."""
        return np.hypot(self.vx_mps, self.vy_mps)


def _times(t_s: ArrayLike) -> np.ndarray:
    t = np.asarray(t_s, dtype=float).reshape(-1)
    if t.size == 0 or not np.all(np.isfinite(t)) or np.any(t < 0):
        raise HiyariError("t_s: sample times must be finite and >= 0")
    return t


def _check_side(side: int) -> None:
    if side not in (1, -1):
        raise HiyariError(f"side must be +1 (left) or -1 (right), got {side!r}")


def _longitudinal(motion: Motion, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, speed, acceleration of a single-row Motion at times t."""
    x, v, a, _ = motion.state_at(np.broadcast_to(t, (1, t.size)))
    return x[0], v[0], a[0]


def _lane_change(
    t: np.ndarray, y_start: float, y_end: float, vy: float
) -> tuple[np.ndarray, np.ndarray]:
    """Lateral centre and velocity: a step to |vy| toward y_end at t = 0, stop when there."""
    direction = np.sign(y_end - y_start)
    t_end = abs(y_end - y_start) / vy
    moving = t < t_end
    y = np.where(moving, y_start + direction * vy * t, y_end)
    return y, np.where(moving, direction * vy, 0.0)


def _track(
    name: str,
    t: np.ndarray,
    x_front: np.ndarray,
    y: np.ndarray,
    vx: np.ndarray,
    vy: np.ndarray,
    ax: np.ndarray,
    length: float,
    width: float,
) -> Track:
    heading = np.where((vx != 0) | (vy != 0), np.arctan2(vy, vx), 0.0)
    return Track(name, t, x_front, y, vx, vy, ax, heading, length, width)


def _cc_ego(setup: ScenarioSetup, t: np.ndarray, p: CCParams) -> Track:
    ego, _ = ego_response(setup, p)
    x, v, a = _longitudinal(ego, t)
    zeros = np.zeros_like(t)
    return _track("cc_ego", t, x, zeros, v, zeros, a, p.ego_length_m, p.ego_width_m)


def cut_in_tracks(
    ve0_mps: float,
    vo0_mps: float,
    dx0_m: float,
    vy_mps: float,
    t_s: ArrayLike,
    params: CCParams = _DEFAULT,
    side: int = 1,
) -> dict[str, Track]:
    """Cut-in: ``"other"`` from the adjacent lane (``side`` +1 left, -1 right) into the ego
    lane, and the ``"cc_ego"`` reference. Inputs as
    :func:`~hiyari.risk.cc.evaluator.evaluate_cut_in` (one scenario)."""
    p = params
    t = _times(t_s)
    _check_side(side)
    y, vy = _lane_change(t, side * p.lane_width_m, 0.0, vy_mps)
    x_front = dx0_m + p.other_length_m + vo0_mps * t
    vx = np.full_like(t, vo0_mps)
    other = _track(
        "other", t, x_front, y, vx, vy, np.zeros_like(t), p.other_length_m, p.other_width_m
    )
    setup = cut_in_setup(*(np.array([v], float) for v in (ve0_mps, vo0_mps, dx0_m, vy_mps)), p)
    return {"other": other, "cc_ego": _cc_ego(setup, t, p)}


def cut_out_tracks(
    ve0_mps: float,
    vy_mps: float,
    dx0_f_m: float,
    t_s: ArrayLike,
    params: CCParams = _DEFAULT,
    side: int = 1,
) -> dict[str, Track]:
    """Cut-out: ``"lead"`` (ahead at ``thw_s`` x Ve0, same speed) moves from the ego lane to
    the adjacent lane (``side``), revealing ``"stopped"`` (dx0_f ahead of the lead's front);
    plus the ``"cc_ego"`` reference."""
    p = params
    t = _times(t_s)
    _check_side(side)
    dx0 = p.thw_s * ve0_mps
    y, vy = _lane_change(t, 0.0, side * p.lane_width_m, vy_mps)
    vx = np.full_like(t, ve0_mps)
    zeros = np.zeros_like(t)
    lead = _track(
        "lead",
        t,
        dx0 + p.other_length_m + ve0_mps * t,
        y,
        vx,
        vy,
        zeros,
        p.other_length_m,
        p.other_width_m,
    )
    stopped_front = dx0 + p.other_length_m + dx0_f_m + p.other_length_m
    stopped = _track(
        "stopped",
        t,
        np.full_like(t, stopped_front),
        zeros,
        zeros,
        zeros,
        zeros,
        p.other_length_m,
        p.other_width_m,
    )
    setup = cut_out_setup(*(np.array([v], float) for v in (ve0_mps, vy_mps, dx0_f_m)), p)
    return {"lead": lead, "stopped": stopped, "cc_ego": _cc_ego(setup, t, p)}


def decel_tracks(
    ve0_mps: float,
    gx_max_g: float,
    t_s: ArrayLike,
    params: CCParams = _DEFAULT,
    dx0_m: float | None = None,
) -> dict[str, Track]:
    """Deceleration: ``"lead"`` ahead at ``dx0_m`` (default ``thw_s`` x Ve0) brakes at
    Gx_max as a step from t = 0 to a stop; plus the ``"cc_ego"`` reference."""
    p = params
    t = _times(t_s)
    dx0 = p.thw_s * ve0_mps if dx0_m is None else dx0_m
    v0, gx = np.array([ve0_mps], float), np.array([gx_max_g], float)
    x, v, a = _longitudinal(Motion.step_deceleration(v0, gx * p.g_mps2), t)
    zeros = np.zeros_like(t)
    lead = _track(
        "lead", t, dx0 + p.other_length_m + x, zeros, v, zeros, a, p.other_length_m, p.other_width_m
    )
    setup = decel_setup(v0, gx, np.array([dx0], float), p)
    return {"lead": lead, "cc_ego": _cc_ego(setup, t, p)}
