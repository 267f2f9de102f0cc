"""The study's baseline drivers yield at zebra crossings (issue 15 item 7): with crossings
that have priority, SUMO's drivers stop for pedestrians; with netconvert's default crossings
(no priority at unsignalised junctions) its turning drivers drive through them."""

from __future__ import annotations

from dataclasses import replace

import pytest
from lxml import etree

from hiyari.bridge.studies.sct.study import StudyConfig, build_inputs, run_arm

pytestmark = [pytest.mark.timeout(600), pytest.mark.slow]

CONFIG = StudyConfig(days=1800 / 86400, runs=1, variants=("unsignalised",), seed=5)


def _crossing_responses(net) -> list[str]:
    """The right-of-way 'response' bits of every crossing link of the junction."""
    junction = next(
        j for j in etree.parse(str(net)).getroot().iter("junction") if j.get("type") == "priority"
    )
    lanes = junction.get("intLanes").split()
    requests = {int(r.get("index")): r.get("response") for r in junction.iter("request")}
    return [requests[k] for k, lane in enumerate(lanes) if "_c" in lane]


def test_zebra_crossings_have_priority(tmp_path):
    zebra = build_inputs(CONFIG, tmp_path / "zebra")[0].net
    minor = build_inputs(replace(CONFIG, crossing_priority=False), tmp_path / "minor")[0].net
    # 4 crossings; with priority they yield to nobody, without it they yield to vehicles
    assert len(_crossing_responses(zebra)) == 4
    assert all(set(r) == {"0"} for r in _crossing_responses(zebra))
    assert all("1" in r for r in _crossing_responses(minor))


@pytest.mark.parametrize("priority", [True, False], ids=["zebra", "minor"])
def test_baseline_drivers_yield_at_zebra_crossings(tmp_path, priority):
    """30 simulated minutes, same demand and seed: contacts at minor crossings, none at zebra
    crossings (2 days with minor crossings gave 308 contacts). One arm per test, so that the
    two arms run side by side on the suite's two workers."""
    cfg = replace(CONFIG, crossing_priority=priority)
    base = next(t for t in build_inputs(cfg, tmp_path) if t.arm == "baseline")
    contacts = sum(e.collision for e in run_arm(base).encounters)
    if priority:
        assert contacts == 0
    else:
        assert contacts > 0


def test_sensitivity_points_and_files(tmp_path):
    """Every grid value plus the main one per parameter; SCT_safe and penetration points share
    their demand's baseline; the CSV and the PNG are written."""
    import csv

    import matplotlib.image

    from hiyari.bridge.studies.report.sct_sensitivity import write_sensitivity
    from hiyari.bridge.studies.sct.sensitivity import SensitivityGrid, run_sensitivity

    grid = SensitivityGrid(sct_safe=(2.0,), penetration=(0.5,), persons_per_hour=(600.0,))
    pts = run_sensitivity(StudyConfig(seed=5), tmp_path, 0.02, grid, jobs=1)
    assert [(p.parameter, p.value) for p in pts] == [
        ("sct_safe", 2.0),
        ("sct_safe", 4.0),
        ("penetration", 0.5),
        ("penetration", 1.0),
        ("persons_per_hour", 300.0),
        ("persons_per_hour", 600.0),
    ]
    assert len({p.baseline_incidents for p in pts[:5]}) == 1  # one baseline at 300 ped/h
    # the main configuration is one SCT arm, whichever parameter lists it
    assert pts[1].sct_incidents == pts[3].sct_incidents == pts[4].sct_incidents
    png = write_sensitivity(tmp_path, pts, 0.02)
    assert matplotlib.image.imread(png).shape[1] > 600
    assert len(list(csv.DictReader((tmp_path / "sensitivity.csv").open()))) == len(pts)
