"""SpeedProfileAction on SUMO: timed entries followed exactly (position), untimed ones at the
DynamicConstraints' acceleration and deceleration, follow mode stretching a timed change the
constraints cannot make, speeds relative to an entity; the action ends with its last entry."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.bridge.openscenario.engine.followers.speed_profile import speed_profile
from hiyari.bridge.openscenario.model.actions import SpeedProfileAction


def test_profile_knots() -> None:
    b = SpeedProfileAction(((20.0, 2.0), (5.0, None), (10.0, 1.0)), "follow", None, 2.0, 5.0)
    times, speeds = speed_profile(b, 10.0, 0.0, 1.0)
    # +10 m/s in 2 s needs 5 s at 2 m/s^2 (follow stretches it); -15 at 5 m/s^2: 3 s; +5: 2.5 s
    assert times.tolist() == [1.0, 6.0, 9.0, 11.5] and speeds.tolist() == [10, 20, 5, 10]
    exact = SpeedProfileAction(((20.0, 2.0),), "position", "Lead", 2.0, 5.0)
    assert speed_profile(exact, 10.0, 3.0, 0.0)[0].tolist() == [0.0, 2.0]  # as timed
    assert speed_profile(exact, 10.0, 3.0, 0.0)[1].tolist() == [10.0, 23.0]  # relative


def test_actor_follows_its_profile(tmp_path: Path) -> None:
    profile = """<LongitudinalAction><SpeedProfileAction followingMode="position">
<DynamicConstraints maxAcceleration="2" maxDeceleration="4"/>
<SpeedProfileEntry speed="14" time="2"/><SpeedProfileEntry speed="6"/></SpeedProfileAction></LongitudinalAction>"""
    init = teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -4, 50, 10)
    stories = story("Car", profile, time_condition(0.99, "go", "none"), "P")
    v = {}

    def on_step(sim, world, report, engine) -> None:
        v[round(report.time + 0.05, 2)] = engine.actors["Car"].v  # a step ahead

    engine, _ = run_scenario(
        write(tmp_path / "p.xosc", scenario_xml({"Ego": "", "Car": ""}, init, stories)),
        tmp_path,
        until=6.0,
        on_step=on_step,
    )
    # the event starts at 1.0: 10 -> 14 m/s by 3.0, then -8 m/s at 4 m/s^2: 6 m/s by 5.0
    assert v[2.0] == pytest.approx(12.0) and v[3.0] == pytest.approx(14.0)
    assert (
        v[4.0] == pytest.approx(10.0)
        and v[5.0] == pytest.approx(6.0)
        and v[5.5] == pytest.approx(6.0)
    )
    ends = [t for t, _, n, tr in engine.tree.log if n == "PAction" and tr == "endTransition"]
    assert ends and ends[0] == pytest.approx(4.95, abs=0.051)


def test_follow_mode_keeps_the_jerk_limits(tmp_path: Path) -> None:
    profile = """<LongitudinalAction><SpeedProfileAction followingMode="follow">
<DynamicConstraints maxAccelerationRate="4" maxDecelerationRate="3"/>
<SpeedProfileEntry speed="20" time="4"/></SpeedProfileAction></LongitudinalAction>"""
    init = teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -4, 50, 10)
    stories = story("Car", profile, time_condition(0.99, "go", "none"), "J")
    seen = {}

    def on_step(sim, world, report, engine) -> None:
        a = engine.actors["Car"]
        seen[round(report.time, 2)] = (a.v, a.accel)

    engine, _ = run_scenario(
        write(tmp_path / "j.xosc", scenario_xml({"Ego": "", "Car": ""}, init, stories)),
        tmp_path,
        until=7.0,
        on_step=on_step,
    )
    start = [t for t, _, n, tr in engine.tree.log if n == "JAction" and tr == "startTransition"]
    end = [t for t, _, n, tr in engine.tree.log if n == "JAction" and tr == "endTransition"]
    # the acceleration builds up by 4 m/s^3 x 0.05 s a step (the old profile jumped to
    # 2.5 m/s^2 in one step), 10 + 0.005 k (k + 1) m/s after k steps (the update at the
    # start moves the actor to the end of the first step)
    steps = [round(start[0] + 0.05 * (k - 1), 2) for k in range(1, 13)]
    assert [seen[t][1] for t in steps] == pytest.approx([0.2 * k for k in range(1, 13)])
    assert [seen[t][0] for t in steps] == pytest.approx(
        [10 + 0.005 * k * (k + 1) for k in range(1, 13)]
    )
    times = sorted(seen)
    jerk = [(seen[b][1] - seen[a][1]) / 0.05 for a, b in zip(times, times[1:], strict=False)]
    assert max(jerk) <= 4.0 + 1e-6 and min(jerk) >= -3.0 - 1e-6
    # build-up 0.625 s, hold 3.2708 s, unwind 0.8333 s: 20 m/s after 4.729 s, not 4 s
    assert end and end[0] - start[0] == pytest.approx(4.729, abs=0.1)
    assert max(v for v, _ in seen.values()) < 20.0 + 2e-3
