"""SynchronizeAction: the actor's speed is set every step so that it reaches its target when
the master reaches the master's target, as the master drives now.

Each step (from the state at time t to t + dt): the master's time to go is T = d_m / v_m (its
remaining distance over its speed; infinite while it stands). Without a final speed the actor
drives at d / T. With a final speed v_f reached ``d_ss`` metres before the target (a steady
state by distance, or by time: d_ss = t_ss v_f), the actor has D = d - d_ss metres and
tau = T - d_ss / v_f seconds to reach v_f: the speed profile v(x) = v0 + a x + b x^2 with
v(tau) = v_f whose integral over tau is D gives a = (6 D - 2 tau (2 v0 + v_f)) / tau^2 and
b = (v_f - v0 - a tau) / tau^2, re-planned every step (so the master's own changes of speed
are followed); the speed at the end of the step is v(dt). Past the steady-state point the
actor holds v_f. The action ends when either entity reaches its target (within its tolerance)
or passes it (its distance grows); the actor then keeps the final speed.

Remaining distances: along the path the entity follows when the target lies on it (within
ON_PATH of it), along the trajectory or route a Trajectory- / RoutePosition target names (the
entity projected on it), along the road when both are on one road, else straight. Metres,
seconds, m/s.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from hiyari.bridge.openscenario.model.actions import SynchronizeAction
from hiyari.bridge.openscenario.model.positions import (
    LanePosition,
    Position,
    RoadPosition,
    RoutePosition,
    TrajectoryPosition,
    WorldPosition,
)

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine

#: A target counts as on a followed path when it lies within this distance of it (a route's
#: reference line beside the lane the actor follows on it), m.
ON_PATH = 5.0
#: Growth of a remaining distance that counts as having passed the target, m.
PASSED = 1e-6
_FIXED = (WorldPosition, LanePosition, RoadPosition, TrajectoryPosition)


class Synchronizer:
    """The speed goal of one running SynchronizeAction on ``actor``."""

    def __init__(self, engine: ScenarioEngine, actor: str, body: SynchronizeAction) -> None:
        self.e, self.actor, self.b = engine, actor, body
        self.done = False
        self._targets: dict[str, object] = {}
        self._last_d = self._last_dm = math.inf
        self._at: tuple[float, float] | None = None  # (time, goal) of the latest evaluation

    def goal(self) -> float:
        """Speed (m/s) the actor is to have at the end of the coming step (evaluated once per
        step; marks the action done when an entity reached or passed its target)."""
        now = self.e.now
        if self._at is not None and self._at[0] == now:
            return self._at[1]
        a, b, dt = self.e.actors[self.actor], self.b, self.e.dt
        d = self.remaining(self.actor, b.target)
        dm = self.remaining(b.master, b.master_target)
        vm = self.e.speed_of(b.master)
        vf = self._final(vm)
        if (
            d <= b.tolerance + PASSED
            or dm <= b.master_tolerance + PASSED
            or d > self._last_d + PASSED
            or dm > self._last_dm + PASSED
            or (vm > 1e-9 and (dm - b.master_tolerance) / vm < dt)
        ):
            self._finish()
            goal = vf if vf is not None else a.v
        else:
            goal = self._speed(a.v, max(d - b.tolerance, 0.0), dm - b.master_tolerance, vm, vf, dt)
        self._last_d, self._last_dm = d, dm
        self._at = (now, goal)
        return goal

    def _finish(self) -> None:
        if not self.done:
            self.done = True
            self.e.table.motion_version += 1  # the storyboard is to end the action

    def _final(self, vm: float) -> float | None:
        b = self.b
        if b.final_speed is None:
            return None
        if b.final_relative == "delta":
            return vm + b.final_speed
        if b.final_relative == "factor":
            return vm * b.final_speed
        return b.final_speed

    def _speed(
        self, v0: float, d: float, dm: float, vm: float, vf: float | None, dt: float
    ) -> float:
        big_t = dm / vm if vm > 1e-9 else math.inf
        if vf is None:
            return d / big_t if math.isfinite(big_t) else 0.0
        d_ss = self.b.steady_distance
        if d_ss is None:
            d_ss = (self.b.steady_time or 0.0) * vf
        big_d = d - d_ss
        tau = big_t - (d_ss / vf if vf > 1e-9 else 0.0)
        if big_d <= 1e-6 or tau <= dt:
            return vf
        if not math.isfinite(tau):
            return 0.0 if v0 <= 0 else max(0.0, v0)  # the master stands: hold (it may go)
        acc = (6.0 * big_d - 2.0 * tau * (2.0 * v0 + vf)) / (tau * tau)
        jerk = (vf - v0 - acc * tau) / (tau * tau)
        return max(0.0, v0 + acc * dt + jerk * dt * dt)

    # ------------------------------------------------------------------ distances
    def remaining(self, name: str, target: Position) -> float:
        """Metres ``name`` still has to go to ``target`` (negative once past it on a path or
        road)."""
        e = self.e
        key = f"{name}:{id(target)}"
        tgt = self._targets.get(key)
        if tgt is None or not isinstance(target, _FIXED):
            tgt = e.resolver.resolve(target)
            self._targets[key] = tgt
        a = e.actors[name]
        motion = a.path if e.storyboard_drives(name) else e.ego_path
        if motion is not None:
            s_t, off = motion.path.project(tgt.x, tgt.y)
            if abs(off) <= ON_PATH:
                return s_t - motion.travelled
        p = e.pose_of(name)
        if a.free and e.storyboard_drives(name):  # its road coordinates are not kept
            p = e.resolver.at_xy(a.x, a.y, a.h)
        if isinstance(target, TrajectoryPosition):
            path = e.resolver.trajectory(target.trajectory)
            return target.s - path.project(p.x, p.y)[0]
        if isinstance(target, RoutePosition):
            line = e.resolver.route_line(target.route)
            return line.project(tgt.x, tgt.y)[0] - line.project(p.x, p.y)[0]
        if p.road and p.road == tgt.road:
            direction = e.travel_direction(name)
            return (tgt.s - p.s) * direction
        return math.hypot(tgt.x - p.x, tgt.y - p.y)
