"""Shared fixtures: small generated networks and demand, built once per test session."""

from __future__ import annotations

from pathlib import Path

import pytest

from hiyari.net.sumo.build import IntersectionParams, build_intersection
from hiyari.traffic.demand import DemandConfig, write_demand

SHARED = Path(__file__).resolve().parents[2] / "shared"


@pytest.fixture(scope="session")
def intersection_net(tmp_path_factory) -> Path:
    """A signalised four-leg intersection with sidewalks and crossings."""
    out = tmp_path_factory.mktemp("net") / "intersection.net.xml"
    return build_intersection(out, IntersectionParams(traffic_light=True))


@pytest.fixture(scope="session")
def intersection_demand(intersection_net, tmp_path_factory) -> Path:
    """Ten minutes of mixed vehicles and pedestrians on the intersection."""
    out = tmp_path_factory.mktemp("demand") / "demand.rou.xml"
    cfg = DemandConfig(
        vehicles_per_hour=1200,
        persons_per_hour=1200,
        end=600,
        seed=7,
        vehicle_mix={"car": 0.7, "truck": 0.1, "bus": 0.1, "motorcycle": 0.1},
    )
    return write_demand(intersection_net, out, cfg)
