"""SpeedProfileAction followingMode="follow" with jerk limits (maxAccelerationRate /
maxDecelerationRate): the acceleration changes within them and every entry's speed is reached
with the acceleration unwound, the times derived by hand from the limits."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.bridge.openscenario.engine.followers.speed_profile import JerkLimited, speed_profile
from hiyari.bridge.openscenario.model.actions import SpeedProfileAction

DT = 0.05
#: 0 -> 10 m/s in 4 s (2.5 m/s^2), -> 4 in 4 s (1.5), -> 8 in 2 s (2); jerk 4 up, 3 down.
PROFILE = SpeedProfileAction(
    ((10.0, 4.0), (4.0, 4.0), (8.0, 2.0)), "follow", None, None, None, None, 4.0, 3.0
)


def _follow(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    times, speeds = speed_profile(PROFILE, 0.0, 0.0, 0.0)
    j = JerkLimited.of(PROFILE, times, speeds)
    v, acc, entry, end = [], [], [], np.nan
    for k in range(1, n + 1):
        v.append(j.step(DT))
        acc.append(j.acc)
        entry.append(j.entry)
        if np.isnan(end) and j.reached():
            end = k * DT
    return np.array(v), np.array(acc), np.array(entry), end


def test_acceleration_builds_up_at_the_jerk_limit() -> None:
    v, acc, _, _ = _follow(20)
    k = np.arange(1, 13)
    # 4 m/s^3: 0.2 m/s^2 more a step up to the entry's 2.5 m/s^2 (after 12.5 steps)
    assert acc[:12] == pytest.approx(0.2 * k, abs=1e-12) and acc[12] == pytest.approx(2.5)
    assert v[:12] == pytest.approx(0.005 * k * (k + 1), abs=1e-12)


def test_jerk_within_its_limits_and_entries_reached_without_overshoot() -> None:
    v, acc, entry, end = _follow(300)
    jerk = np.diff(np.r_[0.0, acc]) / DT
    assert jerk.max() <= 4.0 + 1e-9 and jerk.min() >= -3.0 - 1e-9
    # each entry's speed reached with the acceleration unwound (within a step's rounding)
    assert v[entry <= 1].max() < 10.0 + 2e-3
    assert v[entry == 2].min() > 4.0 - 2e-3 and v[entry == 3].max() < 8.0 + 2e-3
    # each change: build-up a / j_up, hold, unwind a / j_down, the ramps' speed a^2 / (2 j):
    # 0.625 + 3.2708 + 0.8333 = 4.7292 s; 0.5 + 3.5625 + 0.375 = 4.4375 s;
    # 0.5 + 1.4167 + 0.6667 = 2.5833 s: the last speed reached after 11.75 s
    assert end == pytest.approx(11.75, abs=0.1)
    assert v[-1] == pytest.approx(8.0, abs=1e-3) and acc[-1] == pytest.approx(0.0, abs=0.2)
