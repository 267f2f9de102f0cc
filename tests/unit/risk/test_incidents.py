"""The incident detector on scripted encounters: once per pair, collisions as collisions."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from hiyari.errors import HiyariError
from hiyari.risk.metrics.contact import PetEvent
from hiyari.risk.metrics.incidents import (
    IncidentConfig,
    IncidentDetector,
    straight_line_metrics,
    vehicle_pedestrian_pairs,
    write_encounters_csv,
)
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState

DT = 0.1


def state(t: float, actors: list[tuple[str, ActorClass, float, float, float, float]]) -> WorldState:
    """WorldState from (id, class, x, y, heading rad, speed m/s); cars 4.5 x 1.8 m."""
    n = len(actors)
    ped = np.array([a[1] == ActorClass.PEDESTRIAN for a in actors])
    return WorldState(
        time=t,
        ids=np.array([a[0] for a in actors], dtype=object),
        cls=np.array([int(a[1]) for a in actors], np.int8),
        xyz=np.array([[a[2], a[3], 0.0] for a in actors]),
        heading=np.array([a[4] for a in actors], float),
        speed=np.array([a[5] for a in actors], float),
        accel=np.zeros(n),
        length=np.where(ped, 0.3, 4.5),
        width=np.where(ped, 0.5, 1.8),
        height=np.where(ped, 1.7, 1.5),
        lane=np.array([""] * n, dtype=object),
        edge=np.array([""] * n, dtype=object),
    )


def run(script, steps: int, config: IncidentConfig | None = None) -> IncidentDetector:
    config = config or IncidentConfig()
    det = IncidentDetector(config)
    for k in range(steps):
        st = state(round(k * DT, 1), script(k * DT))
        vi, pj = vehicle_pedestrian_pairs(st, config.pair_range)
        ttc, touching = straight_line_metrics(st, vi, pj, config)
        det.update(st, vi, pj, ttc, touching)
    return det


def near_miss(t: float):
    # car at 10 m/s along y = 0; a pedestrian walks towards its path at 1.5 m/s and stops at
    # y = -1.6, 0.4 m clear of the car's side, 0.15 s before the car passes; a far pedestrian
    # walks along the footway
    y = min(-4.0 + 1.5 * t, -1.6)
    v = 1.5 if y > -1.6 or t < 1.6 else 0.0
    return [
        ("car", ActorClass.CAR, -20.0 + 10.0 * t, 0.0, 0.0, 10.0),
        ("ped", ActorClass.PEDESTRIAN, 0.0, y, math.pi / 2, v),
        ("far", ActorClass.PEDESTRIAN, -60.0 + 1.4 * t, 8.0, 0.0, 1.4),
    ]


def test_scripted_near_miss_is_one_incident_without_collision():
    det = run(near_miss, 40)
    (e,) = det.encounters  # the far pedestrian never comes within reach
    assert (e.vehicle, e.pedestrian) == ("car", "ped")
    assert e.is_incident(det.config) and not e.collision
    # at t = 1.5 s (car centre at x = -5, pedestrian at y = -1.75) the pedestrian would meet
    # the car's side (|y| = 0.9 + 0.3) after 0.55 / 1.5 s, while the car covers its x
    assert e.min_ttc <= 0.55 / 1.5 + 1e-9
    assert len(det.incidents()) == 1


def test_scripted_collision_counts_once_as_collision():
    def script(t):  # the pedestrian stands in the lane; the car drives through it
        return [
            ("car", ActorClass.CAR, -10.0 + 8.0 * t, 0.0, 0.0, 8.0),
            ("ped", ActorClass.PEDESTRIAN, 5.0, 0.5, math.pi / 2, 0.0),
        ]

    det = run(script, 30)
    (e,) = det.encounters
    assert e.collision and e.min_ttc == 0.0
    # first contact: front at x = -10 + 8 t + 2.25 reaches 5 - 0.3 when t = 1.55 s
    assert e.time == pytest.approx(1.6)
    assert e.vehicle_speed == 8.0 and e.pedestrian_x == 5.0


def test_threshold_is_a_parameter():
    det = run(near_miss, 40, IncidentConfig(ttc_threshold=0.1))
    (e,) = det.encounters
    assert not e.is_incident(det.config)


def test_pet_and_sumo_collision_inputs():
    det = IncidentDetector()
    st = state(3.0, near_miss(0.0))
    empty = np.zeros(0, int)
    det.update(
        st,
        empty,
        empty,
        np.zeros(0),
        np.zeros(0, bool),
        pet_events=[PetEvent(3.0, "car", "ped", 0.6)],
    )
    (e,) = det.encounters
    assert e.min_pet == pytest.approx(0.6) and e.is_incident(det.config)
    assert e.vehicle_x == -20.0  # the positions of the PET moment
    assert e.pedestrian_y == -4.0
    det.update(st, empty, empty, np.zeros(0), np.zeros(0, bool), sumo_collisions=[("car", "far")])
    far, ped = det.incidents()  # same first sighting: ordered by ids
    assert (far.pedestrian, far.collision) == ("far", True)
    assert (ped.pedestrian, ped.collision) == ("ped", False)


def test_csv_round_trip(tmp_path):
    det = run(near_miss, 40)
    out = write_encounters_csv(tmp_path / "enc.csv", det.encounters, {"arm": "baseline"})
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 1 and rows[0]["arm"] == "baseline"
    assert float(rows[0]["min_ttc"]) == pytest.approx(det.encounters[0].min_ttc)


def test_bad_thresholds():
    with pytest.raises(HiyariError, match="ttc_threshold"):
        IncidentDetector(IncidentConfig(ttc_threshold=0.0))
