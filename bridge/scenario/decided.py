"""End a scripted run once nothing still to simulate can change its judged values.

The UN R157 judge scores a run by whether the ego collided, its impact speed, and the minimum
ground-truth TTC and gap. Once the other vehicles have finished their lateral manoeuvres, what
is left is fixed: they follow their scripts (Annex G: constant speed, or a braking step to a
standstill; never reversing), and the ego cannot go faster than its planner lets it. If even
the fastest ego the planner allows could neither reach a vehicle in its lane, nor come closer
to the target than the minimum gap already scored, nor meet any vehicle with a TTC below the
minimum already scored, before the run's end, the rest of the run cannot change any judged
value: :class:`DecidedEnd` says so and the closed loop stops.

The ego's speed bound is the planner's own law (:class:`~hiyari.bridge.stack.aeb.ACCConfig`):
each step its acceleration is at most ``max(-max_decel, min(max_accel, k_speed * (set_speed
- v)))`` whatever it perceives (the ACC follow term and the AEB only lower it), so from the
current speed ``v0`` the speeds after k steps are bounded by that recurrence (monotone in v,
hence an upper bound by induction), and SUMO moves the ego ``v * dt`` per step at most.
Frames: distances along the ego's lane (straight), seconds of simulation time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.scenario.result import RunResult
from hiyari.bridge.stack.aeb import ACCConfig
from hiyari.risk.metrics.ground_truth import TruthConfig, gap_to
from hiyari.traffic.manoeuvres import ScriptedVehicle
from hiyari.traffic.world_state import WorldState

#: m / s of safety margin on every bound (float noise of positions and TTCs).
_EPS = 1e-6


def speed_envelope(acc: ACCConfig, v0: float, dt: float, n: int) -> np.ndarray:
    """(n,) upper bounds (m/s) on the ego's speed 1..n steps of ``dt`` s from speed ``v0``
    under the ACC law of ``acc`` (see the module docstring)."""
    k = np.arange(1, n + 1, dtype=float)
    if v0 >= acc.set_speed:
        return np.full(n, v0)  # at or above the set speed the ACC never accelerates
    a, ks, vs = acc.max_accel, acc.k_speed, acc.set_speed
    # linear phase while k_speed * (set - v) > max_accel, then a geometric approach to set
    m = max(0, math.ceil((vs - v0 - a / ks) / (a * dt) - 1e-12))
    linear = v0 + a * dt * k
    vm = v0 + a * dt * m
    geometric = vs - (vs - vm) * (1.0 - ks * dt) ** np.maximum(k - m, 0.0)
    return np.where(k <= m, linear, geometric)


@dataclass
class DecidedEnd:
    """The judged-values-decided test of one run (see the module docstring).

    ``acc``: the ego planner's ACC configuration; ``scripted``: the scripted vehicles (any
    other actor makes the test answer False); ``target_id``: the actor whose gap is scored;
    ``start_time`` + ``lead_in``: sim time of script time 0; ``every``: s of simulation time
    between tests; ``grid``: s between the future times sampled (bounds hold between them).
    """

    acc: ACCConfig
    dt: float
    scripted: list
    target_id: str
    start_time: float
    lead_in: float
    every: float = 0.25
    grid: float = 0.25
    truth: TruthConfig = TruthConfig()
    _next: float = -math.inf

    def __call__(self, res: RunResult, world: WorldState, row: int, t_left: float) -> bool:
        """True when the rest of the run (``t_left`` s) cannot change ``res``'s judged values."""
        if world.time < self._next - 1e-9 or res.collision:
            return False
        self._next = world.time + self.every
        if not all(isinstance(a, ScriptedVehicle) for a in self.scripted):
            return False
        n = max(1, math.ceil(t_left / self.dt - 1e-9))
        v_env = speed_envelope(self.acc, float(world.speed[row]), self.dt, n)
        reach = self.dt * np.cumsum(v_env)  # bound on the ego's travel after 1..n steps
        idx = np.unique(np.minimum(np.arange(0, n + 1, max(1, round(self.grid / self.dt))), n))
        idx = np.append(idx, n) if idx[-1] != n else idx
        now = world.time - self.start_time - self.lead_in
        for actor in self.scripted:
            if not self._actor_settled(actor, res, world, row, now, idx, reach, v_env):
                return False
        return True

    def _actor_settled(
        self,
        actor: ScriptedVehicle,
        res: RunResult,
        world: WorldState,
        row: int,
        now: float,
        idx: np.ndarray,
        reach: np.ndarray,
        v_env: np.ndarray,
    ) -> bool:
        if actor.vid not in world.ids:
            return False
        k = world.index(actor.vid)
        xy = world.xyz[:, :2]
        along, beside = gap_to(xy, world.heading, world.length, world.width, row, k)
        samples = np.array([actor.trajectory(now + i * self.dt) for i in idx])
        s, d, vs, vd = samples.T
        if np.any(vd != 0.0) or np.any(d != d[0]) or np.any(vs < 0) or np.any(np.diff(vs) > 0):
            return False  # still manoeuvring, or a script this bound does not cover
        if beside > _EPS:
            return True  # beside the ego's lane for good: never in its way, TTC stays inf
        if along <= 0.0:
            return False  # beside or behind the ego's front: not covered
        # at step j in (idx[i], idx[i + 1]] the actor is at least at s[i] plus its slowest
        # speed over that stretch (speeds never rise) times the time since idx[i]; the ego at
        # most ``reach`` ahead of where it is now
        j = np.arange(1, len(reach) + 1)
        i = np.searchsorted(idx, j, side="left") - 1
        s_lb = s[i] + vs[i + 1] * (j - idx[i]) * self.dt
        gap_lb = along + (s_lb - s[0]) - reach
        floor = res.min_gap if actor.vid == self.target_id else 0.0
        if np.any(gap_lb <= max(floor, 0.0) + _EPS):
            return False
        closing = v_env - vs[i + 1]
        ttc_floor = min(res.min_ttc, self.truth.horizon)
        ttc_lb = np.where(closing > 0, gap_lb / np.maximum(closing, 1e-12), np.inf)
        return bool(np.all(ttc_lb > ttc_floor + _EPS))
