"""SpeedProfileAction: the entries turned into a piecewise-linear speed over time from the
action's start (m/s against s of scenario time), which the actor's speed follows; in
followingMode "follow" with jerk limits (maxAccelerationRate / maxDecelerationRate) the
actor's acceleration changes no faster than they allow, and its speed rounds the profile's
corners (:class:`JerkLimited`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.openscenario.model.actions import SpeedProfileAction

#: Speed error (m/s) within which a jerk-limited follower has reached the profile's end.
REACHED = 1e-3


def speed_profile(
    b: SpeedProfileAction, v0: float, base: float, start: float
) -> tuple[np.ndarray, np.ndarray]:
    """(times, speeds): the knots of the profile from speed ``v0`` at scenario time ``start``;
    ``base`` is added to every entry's speed (the reference entity's speed, else 0)."""
    times, speeds = [start], [v0]
    for speed, duration in b.entries:
        goal = speed + base
        if b.max_speed is not None:
            goal = min(goal, b.max_speed)
        change = goal - speeds[-1]
        limit = b.max_accel if change > 0 else b.max_decel
        needed = abs(change) / limit if limit else 0.0
        if duration is None:
            duration = needed
        elif b.following_mode == "follow":
            duration = max(duration, needed)
        times.append(times[-1] + max(duration, 0.0))
        speeds.append(goal)
    return np.array(times), np.array(speeds)


def _limit(x: float | None) -> float:
    """A DynamicConstraints value as a bound: unbounded when not given (or not positive)."""
    return x if x is not None and x > 0 else math.inf


@dataclass
class JerkLimited:
    """Follows the profile (``times``, ``speeds``) entry by entry with an acceleration that
    changes by at most ``rate_up`` (m/s^3, maxAccelerationRate) upwards and ``rate_down``
    (maxDecelerationRate) downwards per second. Towards each entry's speed the acceleration
    builds up to the slope the profile gives that entry (its change over its duration, as
    ``speed_profile`` stretched it within maxAcceleration / maxDeceleration), holds it, and
    unwinds so that it is 0 when the speed arrives (the time-optimal approach within the
    jerk limits: no more acceleration than about sqrt(2 j e) for an error of e m/s); then the next
    entry. Each change thus takes longer than the profile says, by about the time its
    acceleration takes to build up and unwind (in steps of ``dt``: the bound is the
    discrete one, a (a + j dt) / (2 j) <= e). ``v``, ``acc``: the actor's speed (m/s) and
    acceleration (m/s^2) now; ``entry``: the entry being reached (its knot's index)."""

    times: np.ndarray
    speeds: np.ndarray
    rate_up: float
    rate_down: float
    v: float
    acc: float = 0.0
    entry: int = 1

    @classmethod
    def of(cls, b: SpeedProfileAction, times: np.ndarray, speeds: np.ndarray) -> JerkLimited:
        """The follower of ``b``'s profile from its first knot."""
        rates = _limit(b.max_accel_rate), _limit(b.max_decel_rate)
        return cls(times, speeds, *rates, float(speeds[0]))

    def _slope(self) -> float:
        """The magnitude of the acceleration the current entry's change takes (m/s^2)."""
        k = self.entry
        span = self.times[k] - self.times[k - 1]
        change = abs(self.speeds[k] - self.speeds[k - 1])
        return change / span if span > 0 else math.inf

    def step(self, dt: float) -> float:
        """The speed (m/s) one step of ``dt`` s on."""
        n = len(self.speeds)
        while self.entry < n and abs(self.speeds[self.entry] - self.v) < REACHED:
            self.entry += 1
        aim = 0.0
        if self.entry < n:
            error = float(self.speeds[self.entry]) - self.v
            back = self.rate_down if error > 0 else self.rate_up  # the rate that unwinds it
            size = min(self._slope(), abs(error) / dt)
            if back < math.inf:  # a(a + j dt) / (2 j) <= e: unwound by j dt a step from
                jd = back * dt  # the next speed on, the speed arrives with a = 0
                size = min(size, 0.5 * (math.sqrt(jd * jd + 8.0 * back * abs(error)) - jd))
            aim = math.copysign(size, error)
        self.acc += min(self.rate_up * dt, max(-self.rate_down * dt, aim - self.acc))
        self.v += self.acc * dt
        return self.v

    def reached(self) -> bool:
        """Whether the speed is at the last entry's (every entry reached)."""
        return self.entry >= len(self.speeds) - 1 and abs(self.v - self.speeds[-1]) < REACHED
