"""LongitudinalDistanceAction with continuous = true keeps its gap to the reference every
step while the reference changes speed; an actor placed facing against its lane drives the
other way along it (the Euro NCAP head-on targets)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from openscenario_files import (
    ROADS,
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

KEEP = """<LongitudinalAction><LongitudinalDistanceAction entityRef="Lead" distance="12" freespace="true"
continuous="true" displacement="trailingReferencedEntity" coordinateSystem="road"/></LongitudinalAction>"""
BRAKE = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="rate" value="3"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="4"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""


def test_continuous_gap_follows_a_braking_reference(tmp_path: Path) -> None:
    init = teleport_speed("Ego", -5, 20, 10) + teleport_speed("Lead", -4, 200, 20)
    init += teleport_speed("Follow", -4, 150, 20)
    init += f'<Private entityRef="Follow"><PrivateAction>{KEEP}</PrivateAction></Private>'
    stories = story("Lead", BRAKE, time_condition(1.0, "brake"), "B")
    gaps = []

    def on_step(sim, world, report, engine) -> None:
        lead, fol = engine.actors["Lead"], engine.actors["Follow"]
        gaps.append((report.time, lead.s - fol.s, fol.v, lead.v))

    run_scenario(write(tmp_path / "g.xosc", scenario_xml({"Ego": "", "Lead": "", "Follow": ""}, init, stories)),
                 tmp_path, until=8.0, on_step=on_step)  # fmt: skip
    # bumper to bumper 12 m: reference points 12 + 5 m (both 5 m long, same centre offset)
    assert all(g == pytest.approx(17.0, abs=1e-9) for _, g, _, _ in gaps)
    assert gaps[-1][2] == gaps[-1][3] == pytest.approx(4.0)  # and the lead's speed


def test_actor_facing_against_its_lane_drives_the_other_way(tmp_path: Path) -> None:
    init = teleport_speed("Ego", -4, 20, 10)
    init += """<Private entityRef="Ghost"><PrivateAction><TeleportAction><Position>
<LanePosition roadId="0" laneId="-4" s="300"><Orientation h="3.141592653589793" type="relative"/></LanePosition>
</Position></TeleportAction></PrivateAction>
<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="15"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction></Private>"""
    engine, _ = run_scenario(
        write(tmp_path / "w.xosc", scenario_xml({"Ego": "", "Ghost": ""}, init)),
        tmp_path,
        until=2.0,
    )
    g = engine.actors["Ghost"]
    # 2 s at 15 m/s towards decreasing s (one step ahead: 2.05 s), facing -x
    assert g.s == pytest.approx(300 - 15 * 2.0, abs=1e-9) and g.lane == -4
    assert abs(math.remainder(g.h - math.pi, 2 * math.pi)) < 1e-9


def test_gap_reached_within_dynamic_constraints(tmp_path: Path) -> None:
    drive = """<LongitudinalAction><LongitudinalDistanceAction entityRef="Lead" distance="12" freespace="true"
continuous="false" displacement="trailingReferencedEntity" coordinateSystem="road">
<DynamicConstraints maxAcceleration="2" maxDeceleration="4" maxSpeed="30"/></LongitudinalDistanceAction></LongitudinalAction>"""
    init = teleport_speed("Ego", -5, 20, 10) + teleport_speed("Lead", -4, 200, 15)
    init += teleport_speed("Follow", -4, 120, 15)
    stories = story("Follow", drive, time_condition(0.0, "go", "none"), "D")
    rows = []

    def on_step(sim, world, report, engine) -> None:
        lead, fol = engine.actors["Lead"], engine.actors["Follow"]
        rows.append((report.time, lead.s - fol.s, fol.v))

    engine, _ = run_scenario(write(tmp_path / "d.xosc", scenario_xml({"Ego": "", "Lead": "", "Follow": ""}, init, stories)),
                             tmp_path, until=30.0, on_step=on_step)  # fmt: skip
    v = [r[2] for r in rows]
    acc = [(b - a) / 0.05 for a, b in zip(v, v[1:], strict=False)]
    assert max(acc) <= 2.0 + 1e-9 and min(acc) >= -4.0 - 1e-9 and max(v) <= 30.0
    ends = [t for t, _, n, tr in engine.tree.log if n == "DAction" and tr == "endTransition"]
    assert ends, "the gap was never reached"
    at_end = min(rows, key=lambda r: abs(r[0] - ends[0]))
    assert at_end[1] == pytest.approx(
        17.0, abs=0.15
    )  # 12 m bumper to bumper: 17 m between references


def test_any_displacement_keeps_the_side_the_actor_is_on(tmp_path: Path) -> None:
    """displacement any: the actor behind the reference stays behind it (at s = 200 - 17 once
    put there), the one ahead stays ahead (200 + 17); both 5 m long, centres alike: the 12 m
    bumper-to-bumper gap is 17 m between reference points. The lead drives 20 m/s."""
    keep = KEEP.replace('"trailingReferencedEntity"', '"any"')
    init = teleport_speed("Ego", -5, 20, 10) + teleport_speed("Lead", -4, 200, 20)
    init += teleport_speed("Back", -4, 150, 20) + teleport_speed("Front", -3, 260, 20)
    for name in ("Back", "Front"):
        init += f'<Private entityRef="{name}"><PrivateAction>{keep}</PrivateAction></Private>'
    gaps = []

    def on_step(sim, world, report, engine) -> None:
        lead = engine.actors["Lead"]
        gaps.append((engine.actors["Back"].s - lead.s, engine.actors["Front"].s - lead.s))

    cars = {"Ego": "", "Lead": "", "Back": "", "Front": ""}
    run_scenario(write(tmp_path / "a.xosc", scenario_xml(cars, init)), tmp_path, until=2.0,
                 on_step=on_step)  # fmt: skip
    assert all(b == pytest.approx(-17.0, abs=1e-9) for b, _ in gaps)
    assert all(f == pytest.approx(17.0, abs=1e-9) for _, f in gaps)


def test_gap_in_entity_lane_and_road_coordinates_on_a_curve(tmp_path: Path) -> None:
    """On the road curving left with a 250 m radius, lane -3 (t = -4.5 m: a 254.5 m radius):
    30 m behind the lead measured along the road's s is 30 m of s; along the lane's centre
    line 30 * 250 / 254.5 = 29.4695 m of s; along the lead's heading (the chord's projection
    R sin(phi) = 30) 250 * asin(30 / 254.5) = 29.5382 m of s. All three were 30 before the
    action read its coordinateSystem."""
    expected = {"road": 30.0, "lane": 30.0 * 250.0 / 254.5,
                "entity": 250.0 * math.asin(30.0 / 254.5)}  # fmt: skip
    init = teleport_speed("Ego", -4, 20, 10) + teleport_speed("Lead", -3, 150, 10)
    for system in expected:
        name = f"F{system}"
        init += teleport_speed(name, -3, 60, 10)
        keep = KEEP.replace('distance="12" freespace="true"', 'distance="30" freespace="false"')
        keep = keep.replace('coordinateSystem="road"', f'coordinateSystem="{system}"')
        init += f'<Private entityRef="{name}"><PrivateAction>{keep}</PrivateAction></Private>'
    gaps: dict[str, list[float]] = {s: [] for s in expected}

    def on_step(sim, world, report, engine) -> None:
        for system in expected:
            gaps[system].append(engine.actors["Lead"].s - engine.actors[f"F{system}"].s)

    cars = {"Ego": "", "Lead": "", **{f"F{s}": "" for s in expected}}
    text = scenario_xml(cars, init, road=ROADS / "alks_road_left_radius_250m.xodr")
    run_scenario(write(tmp_path / "c.xosc", text), tmp_path, until=1.0, on_step=on_step)
    for system, want in expected.items():
        # the lane's length is a polyline through points 0.5 m apart (frames.lane.STEP):
        # its chords are short of the arc by L^2 / (24 R^2), 4.8e-6 m over the 30 m
        assert all(g == pytest.approx(want, abs=1e-5) for g in gaps[system]), system
