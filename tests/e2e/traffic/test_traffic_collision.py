"""Collision detection: rectangle geometry by hand, and scripted crashes on real SUMO."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sumolib

from hiyari.kinematics import overlap_depth
from hiyari.traffic import SimConfig, Simulation


def _rect(cx, cy, heading, length, width):
    c, s = np.cos(heading), np.sin(heading)
    f = np.array([c, s]) * length / 2
    left = np.array([-s, c]) * width / 2
    ctr = np.array([cx, cy])
    return np.array([ctr + f + left, ctr - f + left, ctr - f - left, ctr + f - left])


def test_rectangle_overlap_by_hand():
    a = _rect(0, 0, 0, 4, 2)  # x in [-2, 2], y in [-1, 1]
    cases = [
        (_rect(3.5, 0, 0, 4, 2), 0.5),  # x in [1.5, 5.5]: 0.5 m overlap along x
        (_rect(0, 1.8, 0, 4, 2), 0.2),  # y in [0.8, 2.8]: 0.2 m along y
        (_rect(4.5, 0, 0, 4, 2), -0.5),  # 0.5 m apart
        # a square rotated 45 deg whose corner reaches 0.3 m into a's front face
        (_rect(2 + np.sqrt(2) - 0.3, 0, np.pi / 4, 2, 2), 0.3),
    ]
    for b, expected in cases:
        d = overlap_depth(a[None], b[None])[0]
        assert d == pytest.approx(expected, abs=1e-9)


def _start(net):
    sim = Simulation(SimConfig(net=net, step_length=0.1, seed=1))
    sim.start()
    return sim


ROUTE = ("w_in", "e_out")


def test_rear_end_reported_with_ids(intersection_net):
    sim = _start(intersection_net)
    try:
        sim.add_vehicle("lead", ROUTE, "DEFAULT_VEHTYPE", "best", 100.0, 0.0, scripted=False)
        sim.add_vehicle("follow", ROUTE, "DEFAULT_VEHTYPE", "best", 20.0, 15.0, scripted=False)
        sim.step()
        sim.set_speed("lead", 0.0)
        sim.set_speed_mode("follow", 0)  # ignore safe speeds: drive into the leader
        sim.set_speed("follow", 15.0)
        hits = []
        for _ in sim.run(until=15.0):
            hits += sim.collisions
            if hits:
                break
    finally:
        sim.close()
    assert hits, "no collision detected"
    c = hits[0]
    assert (c.a, c.b) == ("follow", "lead")
    assert c.kind == "vehicle-vehicle"
    # contact happens when the 80 m gap minus the leader's length is closed at 15 m/s
    assert 4.0 < c.time < 6.5


def test_pedestrian_in_lane_is_hit(intersection_net):
    net = sumolib.net.readNet(str(intersection_net))
    lane = net.getLane("w_in_1")  # lane 0 is the sidewalk
    x, y = sumolib.geomhelper.positionAtShapeOffset(lane.getShape(), 90.0)
    sim = _start(intersection_net)
    try:
        sim.add_person("ped", "w_in", 85.0, "DEFAULT_PEDTYPE", wait=100.0)
        sim.add_vehicle("car", ROUTE, "DEFAULT_VEHTYPE", "best", 10.0, 12.0, scripted=False)
        sim.step()
        sim.set_speed_mode("car", 0)
        sim.set_speed("car", 12.0)
        hits, gaps = [], []
        for state in sim.run(until=12.0):
            sim.move_person("ped", x, y, math.pi / 2, edge="w_in")  # facing north
            if "ped" in state.ids and "car" in state.ids:
                gaps.append(
                    np.linalg.norm(
                        state.xyz[state.index("ped"), :2] - state.xyz[state.index("car"), :2]
                    )
                )
            hits += [c for c in sim.collisions if "ped" in (c.a, c.b)]
            if hits:
                break
    finally:
        sim.close()
    assert hits, f"pedestrian never hit (closest centre gap {min(gaps):.2f} m)"
    assert (hits[0].a, hits[0].b) == ("car", "ped")
    assert hits[0].kind == "vehicle-pedestrian"


def test_no_collisions_in_ordinary_traffic(intersection_net, intersection_demand):
    """SUMO's own drivers keep their gaps: ordinary traffic gives (almost) no contacts."""
    pairs = set()
    with Simulation(SimConfig(net=intersection_net, routes=[intersection_demand])) as sim:
        for _ in sim.run(until=120.0):
            pairs.update((c.a, c.b) for c in sim.collisions)
    assert len(pairs) <= 2, pairs
