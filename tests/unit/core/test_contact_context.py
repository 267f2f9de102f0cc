"""A traffic run's contacts explained: which actors, where, why (the demo's four contacts of
5 minutes at a signalised junction are three centimetre overlaps of vehicles on conflicting
paths inside the junction and one turning bus over the kerb)."""

from __future__ import annotations

import math

import numpy as np

from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.collision import Collision
from hiyari.traffic.contact_context import explain, place, reason_counts
from hiyari.traffic.world_state import WorldState


def _state(actors: list[tuple]) -> WorldState:
    """(id, class, x, y, heading deg, speed, length, lane) per actor."""
    n = len(actors)
    return WorldState(
        time=1.0,
        ids=np.array([a[0] for a in actors], dtype=object),
        cls=np.array([int(a[1]) for a in actors], np.int8),
        xyz=np.array([[a[2], a[3], 0.0] for a in actors]),
        heading=np.radians([a[4] for a in actors]),
        speed=np.array([a[5] for a in actors], float),
        accel=np.zeros(n),
        length=np.array([a[6] for a in actors], float),
        width=np.full(n, 1.8),
        height=np.full(n, 1.5),
        lane=np.array([a[7] for a in actors], dtype=object),
        edge=np.array([a[7].rsplit("_", 1)[0] for a in actors], dtype=object),
    )


def test_places_from_lane_ids():
    assert place(":C_7_0") == "junction C"
    assert place(":J_1_3_0") == "junction J_1"
    assert place(":C_c0_0") == "crossing of junction C"
    assert place(":C_w1_0") == "walking area of junction C"
    assert place("s_in_0") == "edge s_in"
    assert place("") == "off the road network"


def test_contacts_explained():
    st = _state([
        ("bus", ActorClass.BUS, 148.9, 159.4, -83.2, 0.8, 12.0, ":C_2_0"),
        ("car", ActorClass.CAR, 151.8, 152.4, 90.0, 7.2, 4.5, ":C_7_0"),
        ("turner", ActorClass.BUS, 153.1, 141.8, 75.4, 2.2, 12.0, ":C_16_0"),
        ("ped", ActorClass.PEDESTRIAN, 153.8, 142.6, -90.0, 1.2, 0.3, "s_in_0"),
        ("lead", ActorClass.CAR, 100.0, 0.0, 0.0, 0.0, 4.5, "w_in_1"),
        ("follower", ActorClass.CAR, 95.6, 0.0, 0.0, 3.0, 4.5, "w_in_1"),
    ])  # fmt: skip
    junction = explain(Collision(1.0, "bus", "car", "vehicle-vehicle", 0.043, True), st)
    assert (junction.where, junction.reason) == ("junction C", "junction model")
    assert "headings 173° apart" in junction.why and "overlap 4 cm" in junction.why
    assert (junction.a_class, junction.b_lane, junction.b_speed) == ("bus", ":C_7_0", 7.2)
    deep = explain(Collision(1.0, "bus", "car", "vehicle-vehicle", 0.5, False), st)
    assert deep.reason == "other" and "not a crash" not in deep.why
    kerb = explain(Collision(1.0, "ped", "turner", "vehicle-pedestrian", 0.215, False), st)
    assert kerb.reason == "turning sweep over the kerb" and "12 m bus" in kerb.why
    assert kerb.where == "edge s_in / junction C"
    rear = explain(Collision(1.0, "follower", "lead", "vehicle-vehicle", 0.1, False), st)
    assert rear.reason == "rear-end"
    gone = explain(Collision(1.0, "car", "teleported", "vehicle-vehicle", 0.0, True), st)
    assert gone.reason == "other" and math.isnan(gone.a_speed)
    assert reason_counts([junction, junction, kerb]) == (
        "2 junction model, 1 turning sweep over the kerb"
    )
