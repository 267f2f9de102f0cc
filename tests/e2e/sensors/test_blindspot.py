"""Blind-spot catalogue: the text's position sets, the reduction, and the ray-cast occlusion."""

from __future__ import annotations

from collections import Counter

import pytest

from hiyari.bridge.studies.perception.blindspot.catalogue import (
    BLIND_BY_GEOMETRY,
    GRID,
    Geometry,
    Motion,
    combinations,
    mirror,
    occluder_cases,
)
from hiyari.bridge.studies.perception.blindspot.occlusion import HIDDEN_BELOW, OcclusionProbe
from hiyari.bridge.studies.perception.blindspot.road import pose
from hiyari.bridge.studies.perception.blindspot.run import check_occlusion
from hiyari.bridge.studies.perception.blindspot.scenarios import initial_world


def test_grid_and_text_counts():
    assert len(GRID) == 24 and len(set(GRID.values())) == 24  # 8 + 16 positions
    # jama-C 7.1: occluder 1 blinds 9 distinct positions over the three geometries
    assert len(set().union(*BLIND_BY_GEOMETRY[1].values())) == 9
    assert len(BLIND_BY_GEOMETRY[4][Geometry.RIGHT]) == 11
    assert mirror(3) == 6 and mirror(mirror(16)) == 16


def test_reduction_counts_and_rules():
    combos = combinations()
    assert len(occluder_cases()) == 5  # the worked 1, 4, 3 and mirrors 7, 6
    assert len(combos) == 23 * 5
    ok = [c for c in combos if c.realisable]
    assert len(ok) == 46  # the seed's 64 / 42 rest on the lost Fig. 75 (README)
    assert not any(c.motion == Motion.SYNC for c in ok)
    rear = {p for p, (_, slot) in GRID.items() if slot < 0}
    assert not any(c.motion == Motion.DECELERATE and c.hidden in rear for c in ok)
    assert Counter(c.geometry for c in ok)[Geometry.STRAIGHT] == 22


def test_pose_on_the_left_curve_by_hand():
    # lane -3 centre is 8.75 m right of the reference line; after 140 m on R 280 m heading 0.5
    x, y, h = pose(Geometry.LEFT, -3, 140.0)
    assert h == pytest.approx(0.5)
    assert x == pytest.approx(280 * 0.479426 + 8.75 * 0.479426, rel=1e-5)
    assert y == pytest.approx(280 * (1 - 0.877583) - 8.75 * 0.877583, rel=1e-5)


def test_truck_ahead_hides_the_cut_in_car_from_the_lidar():
    combo = next(
        c for c in combinations()
        if (c.occluder, c.hidden, c.motion) == (1, 11, Motion.CUT_IN)
    )  # fmt: skip
    assert combo.geometry == Geometry.LEFT
    probe = OcclusionProbe()
    shift, fraction = check_occlusion(combo, probe)
    assert fraction < HIDDEN_BELOW
    world = initial_world(combo, shift)
    clear = probe.returns_on(world.select(world.ids != "occluder"), "hidden")
    assert clear >= 15  # without the truck the LiDAR sees the car well
    assert probe.returns_on(world, "hidden") < HIDDEN_BELOW * clear


def test_one_case_in_closed_loop_on_sumo(tmp_path):
    from hiyari.bridge.studies.perception.blindspot.run import run_catalogue
    from hiyari.bridge.studies.report.blindspot import write_catalogue

    name = "occ1-hid11-cut-in-left"
    (res,) = run_catalogue(tmp_path, only=[name], progress=False)
    assert res.hidden and res.collision is False  # it cuts in ahead of the truck the ego follows
    assert res.aeb_max_stage == 0
    assert (tmp_path / "blindspot_left.xodr").exists()
    md = write_catalogue([res], tmp_path)["md"].read_text()
    assert f"| {name} | left curve |" in md
