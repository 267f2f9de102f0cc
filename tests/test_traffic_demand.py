"""Seeded demand generation."""

from __future__ import annotations

import pytest
from lxml import etree

from hiyari.errors import HiyariError
from hiyari.traffic import DemandConfig, write_demand


def test_same_seed_same_bytes_and_rates(intersection_net, tmp_path):
    cfg = DemandConfig(
        vehicles_per_hour=720,
        persons_per_hour=360,
        end=3600,
        seed=5,
        vehicle_mix={"car": 0.5, "truck": 0.5},
    )
    a = write_demand(intersection_net, tmp_path / "a.rou.xml", cfg).read_bytes()
    b = write_demand(intersection_net, tmp_path / "b.rou.xml", cfg).read_bytes()
    assert a == b
    c = write_demand(
        intersection_net, tmp_path / "c.rou.xml", DemandConfig(**{**cfg.__dict__, "seed": 6})
    ).read_bytes()
    assert a != c
    root = etree.fromstring(a)
    trips = root.findall("trip")
    persons = root.findall("person")
    # Poisson counts: 720 +- 4 sigma (sigma = sqrt(720) ~ 27), 360 +- 4 * 19
    assert abs(len(trips) - 720) < 110 and abs(len(persons) - 360) < 76
    types = {t.get("type") for t in trips}
    assert types == {"car", "truck"}
    departs = [float(t.get("depart")) for t in trips]
    assert departs == sorted(departs) and departs[-1] < 3600
    assert all(t.get("from") != t.get("to") for t in trips)


def test_bad_demand_refused(intersection_net, tmp_path):
    with pytest.raises(HiyariError, match="unknown vehicle type 'tank'"):
        write_demand(
            intersection_net, tmp_path / "x.rou.xml", DemandConfig(vehicle_mix={"tank": 1})
        )
    with pytest.raises(HiyariError, match=">= 0"):
        write_demand(intersection_net, tmp_path / "x.rou.xml", DemandConfig(vehicles_per_hour=-1))
    assert not (tmp_path / "x.rou.xml").exists()
