"""SpeedProfileAction: the entries turned into a piecewise-linear speed over time from the
action's start (m/s against s of scenario time), which the actor's speed follows."""

from __future__ import annotations

import numpy as np

from hiyari.bridge.openscenario.model.actions import SpeedProfileAction


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
