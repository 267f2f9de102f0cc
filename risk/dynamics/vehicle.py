"""Planar single-track (bicycle) model with a friction circle per axle, following a path.

State in the path frame: station s, lateral offset e_y (m, + left), heading error e_psi (rad),
body velocities vx, vy (m/s) and yaw rate r (rad/s). Linear tyres (cornering stiffness) give
the demanded axle forces; each axle's resultant is capped at mu Fz (the friction circle), and
the demand over the cap is the axle's grip use. The driver / controller steers with the
steady-state feed-forward (L + K v^2) k plus feedback on e_y and e_psi and holds the
reference speed with a force shared between the axles in proportion to their load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.errors import HiyariError
from hiyari.units import G

AIR_DENSITY = 1.2
"""kg/m^3 at about 20 C, sea level."""
DEPARTURE_M = 1.0
"""Lateral offset from the lane centre at which a run counts as a lane departure and stops, m
(a 1.8 m car in a 3.5 m lane touches the line at 0.85 m)."""


@dataclass(frozen=True)
class VehicleParams:
    """A mid-size sedan (toolkit choice; typical published values)."""

    mass: float = 1500.0
    """kg."""
    yaw_inertia: float = 2500.0
    """kg m^2."""
    lf: float = 1.2
    """CG to front axle, m."""
    lr: float = 1.6
    """CG to rear axle, m."""
    cf: float = 90000.0
    """Front axle cornering stiffness, N/rad."""
    cr: float = 110000.0
    """Rear axle cornering stiffness, N/rad (more than the front: understeer)."""
    frontal_area: float = 2.2
    """m^2."""
    side_force_slope: float = 2.5
    """Aerodynamic side-force coefficient per radian of relative-wind yaw angle, referred to
    the frontal area (toolkit choice; passenger cars 2-3 / rad)."""

    def __post_init__(self) -> None:
        for name in ("mass", "yaw_inertia", "lf", "lr", "cf", "cr", "frontal_area"):
            if not getattr(self, name) > 0:
                raise HiyariError(f"vehicle parameter {name} must be positive")

    @property
    def wheelbase(self) -> float:
        """m."""
        return self.lf + self.lr

    @property
    def understeer_gradient(self) -> float:
        """Understeer term K in the steady-state steer angle delta = (L + K v^2) k, s^2."""
        m, L = self.mass, self.wheelbase
        return m * (self.lr / self.cf - self.lf / self.cr) / L


def crosswind_force(
    params: VehicleParams, speed: np.ndarray | float, wind: np.ndarray | float
) -> np.ndarray:
    """Aerodynamic side force, N (+ left), of a crosswind ``wind`` m/s (+ blowing to the
    left) on a car at ``speed`` m/s: q (v^2 + w^2) A C_y(beta), beta = atan(w / v)."""
    v, w = np.asarray(speed, float), np.asarray(wind, float)
    beta = np.arctan2(w, np.maximum(v, 0.1))
    q = 0.5 * AIR_DENSITY * (v**2 + w**2)
    return q * params.frontal_area * params.side_force_slope * beta


@dataclass(frozen=True)
class Disturbances:
    """Along-path disturbances as arrays on a station grid (all m or per-metre)."""

    s: np.ndarray
    """Uniform station grid, m (at least two stations)."""
    curvature: np.ndarray
    """Path curvature, 1/m (+ left)."""
    cross_slope: np.ndarray
    """tan(bank), + falling to the left."""
    mu: np.ndarray
    """Road friction coefficient."""
    wind: np.ndarray
    """Crosswind, m/s (+ blowing to the left)."""
    rut_accel: np.ndarray
    """Lateral acceleration from rut flanks, m/s^2 (+ left)."""


@dataclass(frozen=True)
class Run:
    """Time series of one run."""

    t: np.ndarray
    s: np.ndarray
    speed: np.ndarray
    e_y: np.ndarray
    ay: np.ndarray
    """Lateral acceleration, m/s^2."""
    grip_use: np.ndarray
    """Max over the two axles of demanded force / (mu Fz)."""
    mu: np.ndarray
    departed_at: float | None
    """Station where the ego left its lane (|e_y| > DEPARTURE_M), None when it stayed."""


def simulate(
    road: Disturbances,
    speed: float,
    params: VehicleParams | None = None,
    dt: float = 0.01,
) -> Run:
    """Drive the path at ``speed`` m/s from station road.s[0] to road.s[-1] (explicit Euler)."""
    p = params or VehicleParams()
    if not speed > 0:
        raise HiyariError(f"speed must be positive, got {speed}")
    if len(road.s) < 2 or not np.allclose(np.diff(road.s), road.s[1] - road.s[0]):
        raise HiyariError("disturbance profile needs a uniform station grid of >= 2 stations")
    m, L = p.mass, p.wheelbase
    fz = np.array([m * G * p.lr / L, m * G * p.lf / L])
    K = p.understeer_gradient
    n = int(math.ceil((road.s[-1] - road.s[0]) / (speed * dt) * 1.5)) + 10
    out = np.full((n, 7), np.nan)
    table = np.column_stack(
        [road.curvature, road.cross_slope, road.mu, road.wind, road.rut_accel]
    ).tolist()
    s0, step, last = float(road.s[0]), float(road.s[1] - road.s[0]), len(road.s) - 2
    s, ey, epsi, vx, vy, r = s0, 0.0, 0.0, speed, 0.0, 0.0
    k, departed = 0, None
    while s < road.s[-1] and k < n:
        j = min(int((s - s0) / step), last)
        f = (s - s0) / step - j
        kap, i, mu, w, ar = (a + f * (b - a) for a, b in zip(table[j], table[j + 1], strict=True))
        delta = (L + K * vx**2) * kap - 0.05 * ey - 0.5 * epsi
        fx = m * 1.0 * (speed - vx)
        alpha_f = (vy + p.lf * r) / vx - delta
        alpha_r = (vy - p.lr * r) / vx
        fy_demand = np.array([-p.cf * alpha_f, -p.cr * alpha_r])
        fx_axle = fx * fz / fz.sum()
        demand = np.hypot(fx_axle, fy_demand)
        cap = np.minimum(1.0, mu * fz / np.maximum(demand, 1e-9))
        fyf, fyr = fy_demand * cap
        fx_eff = float((fx_axle * cap).sum())
        f_ext = m * G * i + float(crosswind_force(p, vx, w)) + m * ar
        ay = (fyf * math.cos(delta) + fyr + f_ext) / m
        out[k] = (k * dt, s, vx, ey, ay, float((demand / (mu * fz)).max()), mu)
        s_dot = (vx * math.cos(epsi) - vy * math.sin(epsi)) / (1.0 - kap * ey)
        vx += dt * (fx_eff / m + vy * r)
        vy += dt * (ay - vx * r)
        r += dt * (p.lf * fyf * math.cos(delta) - p.lr * fyr) / p.yaw_inertia
        ey += dt * (vx * math.sin(epsi) + vy * math.cos(epsi))
        epsi += dt * (r - kap * s_dot)
        s += dt * s_dot
        k += 1
        if abs(ey) > DEPARTURE_M:
            departed = s
            break
    o = out[:k]
    return Run(*(o[:, j] for j in range(7)), departed_at=departed)
