"""End a scripted run once nothing still to simulate can change its judged values.

The UN R157 judge scores a run by whether the ego collided, its impact speed, and the minimum
ground-truth TTC and gap. Once every event of the storyboard has started and the other
vehicles have finished their lateral manoeuvres, what is left is fixed: the ScenarioEngine
moves them on their lanes at their speeds, or through a running speed transition to a fixed
target (Annex G: constant speed, or a braking step to a standstill; never reversing), and the
ego cannot go faster than its planner lets it. If even
the fastest ego the planner allows could neither reach a vehicle in its lane, nor come closer
to the target than the minimum gap already scored, nor meet any vehicle with a TTC below the
minimum already scored, before the run's end, the rest of the run cannot change any judged
value: :class:`DecidedEnd` says so and the closed loop stops.

The ego's speed bound is the planner's own law (:class:`~hiyari.bridge.loop.stack.aeb.ACCConfig`):
each step its acceleration is at most ``max(-max_decel, min(max_accel, k_speed * (set_speed
- v)))`` whatever it perceives (the ACC follow term and the AEB only lower it), so from the
current speed ``v0`` the speeds after k steps are bounded by that recurrence (monotone in v,
hence an upper bound by induction), and SUMO moves the ego ``v * dt`` per step at most.
Frames: distances along the lanes (straight), seconds of simulation time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.loop.result import RunResult
from hiyari.bridge.loop.stack.aeb import ACCConfig
from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.engine.elements import STANDBY
from hiyari.bridge.openscenario.engine.kernels.motion_kernel import L_GOAL, L_REACHED
from hiyari.bridge.openscenario.engine.kernels.shapes import progress
from hiyari.bridge.openscenario.engine.motion import Actor
from hiyari.bridge.openscenario.model.entities import EntityKind
from hiyari.risk.metrics.ground_truth import TruthConfig, gap_to
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

    ``acc``: the ego planner's ACC configuration; ``engine``: the run's ScenarioEngine (its
    actors' state and transitions give their future); ``target_id``: the actor whose gap is
    scored; ``every``: s of simulation time between tests; ``grid``: s between the future
    times sampled (bounds hold between them).
    """

    acc: ACCConfig
    dt: float
    engine: ScenarioEngine
    target_id: str
    every: float = 0.25
    grid: float = 0.25
    truth: TruthConfig = TruthConfig()
    _next: float = -math.inf

    @staticmethod
    def of(engine: ScenarioEngine, acc: ACCConfig, dt: float, target_id: str) -> DecidedEnd | None:
        """The test for a run of ``engine``; None where it does not apply: no ego, an ego the
        storyboard drives, no other actor, or a pedestrian."""
        others = [e for e in engine.scenario.entities if e.name != engine.ego]
        if engine.ego is None or not others or engine.storyboard_drives(engine.ego):
            return None
        if any(e.kind == EntityKind.PEDESTRIAN for e in others):
            return None
        return DecidedEnd(acc, dt, engine, target_id)

    def __call__(self, res: RunResult, world: WorldState, row: int, t_left: float) -> bool:
        """True when the rest of the run (``t_left`` s) cannot change ``res``'s judged values."""
        if world.time < self._next - 1e-9 or res.collision:
            return False
        self._next = world.time + self.every
        eng = self.engine
        events = [e.index for e in eng.tree.of_kind("event") if e.model is not None]
        if eng.finished or any(eng.tree.state[i] == STANDBY for i in events):
            return False  # a stop trigger ends the run, an event still to come can change it
        n = max(1, math.ceil(t_left / self.dt - 1e-9))
        v_env = speed_envelope(self.acc, float(world.speed[row]), self.dt, n)
        reach = self.dt * np.cumsum(v_env)  # bound on the ego's travel after 1..n steps
        idx = np.unique(np.minimum(np.arange(0, n + 1, max(1, round(self.grid / self.dt))), n))
        idx = np.append(idx, n) if idx[-1] != n else idx
        for name, actor in eng.actors.items():
            if name == eng.ego:
                continue
            if not self._actor_settled(actor, res, world, row, idx, reach, v_env):
                return False
        return True

    def _future(self, a: Actor, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """Distance travelled along its lane (m) and speed (m/s) of ``a`` at steps ``idx`` from
        the current state; None while it moves laterally or off its lane, or its speed target
        is not fixed."""
        if a.free or a.path is not None or a.lat is not None or a.v_lat != 0.0 or not a.road:
            return None
        # the engine has already advanced its actors to the next step
        steps = np.arange(idx[-1] + 1)
        v = np.full(len(steps), a.v)
        tr = a.long
        if tr is not None:
            if tr.continuous or tr.by_distance:
                return None
            par = a.table.long_par[
                a.k
            ]  # the goal and whether it was reached, as the kernel has them
            goal, reached = par[L_GOAL], par[L_REACHED] != 0.0
            x = (
                (self.engine.now + steps * self.dt - tr.t0) / tr.span
                if tr.span > 0
                else steps + 1.0
            )
            frac = np.array([progress(tr.shape, float(xi)) for xi in x])
            v = np.where(reached | (x >= 1.0 - 1e-9), goal, tr.v0 + (goal - tr.v0) * frac)
        v[0] = a.v - a.accel * self.dt
        s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * self.dt)])
        return s[idx], v[idx]

    def _actor_settled(
        self,
        actor: Actor,
        res: RunResult,
        world: WorldState,
        row: int,
        idx: np.ndarray,
        reach: np.ndarray,
        v_env: np.ndarray,
    ) -> bool:
        if actor.name not in world.ids:
            return False
        future = self._future(actor, idx)
        if future is None:
            return False  # still manoeuvring, or motion this bound does not cover
        s, vs = future
        if np.any(vs < 0) or np.any(np.diff(vs) > 0):
            return False
        k = world.index(actor.name)
        xy = world.xyz[:, :2]
        along, beside = gap_to(xy, world.heading, world.length, world.width, row, k)
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
        floor = res.min_gap if actor.name == self.target_id else 0.0
        if np.any(gap_lb <= max(floor, 0.0) + _EPS):
            return False
        closing = v_env - vs[i + 1]
        ttc_floor = min(res.min_ttc, self.truth.horizon)
        ttc_lb = np.where(closing > 0, gap_lb / np.maximum(closing, 1e-12), np.inf)
        return bool(np.all(ttc_lb > ttc_floor + _EPS))
