"""The JAMA traffic-disturbance catalogue: combinations, the geometric obstruction test and its
expansion over positions and lane counts, and the generated OpenDRIVE roads (real netconvert)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hiyari.bridge.studies.catalogue.space.obstruction import expand
from hiyari.bridge.studies.catalogue.space.taxonomy import (
    EgoMotion,
    Geometry,
    Motion,
    Position,
    general_combinations,
    motorway_combinations,
)
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.sumo.build import CatalogueRoadParams, build_catalogue_road, xodr_beside


def _cell(key: str, position: Position, lanes: int, general: bool = False):
    combos = general_combinations() if general else motorway_combinations()
    combo = next(c for c in combos if c.key == key)
    return next(c for c in expand(combo) if c.position == position and c.lanes == lanes)


def test_exactly_24_motorway_combinations_numbered_as_fig_48() -> None:
    combos = motorway_combinations()
    assert len(combos) == 24
    assert len({(c.geometry, c.ego, c.motion) for c in combos}) == 24
    assert {c.geometry for c in combos} == {Geometry.MAIN, Geometry.MERGE, Geometry.BRANCH}
    # the text: No. 5-8 are single road, ego lane change, surrounding straight / lane change
    five_to_eight = [c for c in combos if 5 <= c.no <= 8]
    assert {(c.geometry, c.ego) for c in five_to_eight} == {(Geometry.MAIN, EgoMotion.LANE_CHANGE)}
    assert [c.motion for c in five_to_eight] == [
        Motion.ACCELERATE, Motion.DECELERATE, Motion.CUT_IN, Motion.CUT_OUT
    ]  # fmt: skip


def test_every_combination_states_each_position_and_lane_count_with_a_reason() -> None:
    for combo in motorway_combinations():
        cells = expand(combo)
        assert len(cells) == 7 * 2  # 6 around the ego + "+1", on 2 and 3 lanes
        for cell in cells:
            assert cell.reason, cell.key
            assert cell.valid == (cell.status == "obstructs")


def test_cut_in_from_the_rear_left_on_two_lanes_is_generated() -> None:
    cell = _cell("M03", Position.LEFT_REAR, 2)  # main line, ego lane keep, cut-in
    assert cell.valid, cell.reason
    # on two lanes the ego drives in the right lane: nothing to its right
    right = _cell("M03", Position.RIGHT_REAR, 2)
    assert right.status == "no lane"
    assert _cell("M03", Position.RIGHT_REAR, 3).valid  # three lanes: the middle lane


def test_turn_by_the_rear_vehicle_is_excluded_as_non_obstructing() -> None:
    for key in ("G33", "G34"):  # intersection, ego straight; actor turns left / right
        rear = _cell(key, Position.REAR, 1, general=True)
        assert rear.status == "non-obstructing", rear.reason
    # the same turn from the crossing road does cross the ego's path
    assert _cell("G33", Position.CROSSING_LEFT, 1, general=True).valid


def test_vehicles_behind_a_lane_keeping_ego_do_not_obstruct_it() -> None:
    """Accelerating into the ego from behind is the follower's doing, not an obstruction."""
    assert _cell("M01", Position.REAR, 2).status == "non-obstructing"
    # but the same vehicle in the lane the ego changes into does obstruct it
    assert _cell("M05", Position.LEFT_REAR, 2).valid
    assert _cell("M02", Position.PLUS_ONE, 2).status == "shielded"
    assert _cell("M02", Position.FRONT, 2).valid


@pytest.mark.parametrize("geometry", ["merge", "branch"])
def test_generated_roads_have_the_extra_lane_where_stated(tmp_path: Path, geometry: str) -> None:
    net = build_catalogue_road(
        tmp_path / f"{geometry}.net.xml", CatalogueRoadParams(lanes=3, station=700.0), geometry
    )
    roads = RoadLanes.from_files(xodr_beside(net), net)
    before, after = (300.0, 1100.0) if geometry == "merge" else (1100.0, 300.0)
    assert roads.sumo_lane("main", -4, before) is not None
    assert roads.sumo_lane("main", -4, after) is None
    for lane in (-1, -2, -3):
        p = roads.place("main", lane, 1000.0)
        assert np.isclose(p.y, -(abs(lane) - 0.5) * 3.5, atol=0.05)
        assert roads.origin_of(p.sumo_lane)[:2] == ("main", lane)


def test_exported_case_reads_back_as_the_same_scenario(tmp_path: Path) -> None:
    """.xosc + .xodr export: hiyari's XSD-validating reader gets the same entities, Init
    positions and speeds, and the surrounding vehicle's manoeuvre."""
    from hiyari.bridge.openscenario.xosc.reader import read_scenario
    from hiyari.bridge.studies.catalogue.evaluation.campaign import case_by_id, catalogue_cells
    from hiyari.bridge.studies.catalogue.space.concrete import concrete_cases, to_scenario
    from hiyari.bridge.studies.catalogue.space.xosc_export import export_case

    case = case_by_id("M04-front-2L-003")
    cell = next(c for c in catalogue_cells("motorway") if c.key == "M04-front-2L")
    assert case.params == concrete_cases(cell, 14)[3].params  # same case whatever the count
    path = export_case(case, tmp_path / "roads", tmp_path / "xosc")
    assert (tmp_path / "xosc" / "main-2.xodr").is_file()
    back, model = read_scenario(path), to_scenario(case)
    assert [e.name for e in back.entities] == ["ego", "actor", "plus1"]
    assert [(i.entity, i.action.body) for i in back.storyboard.init] == [
        (i.entity, i.action.body) for i in model.storyboard.init
    ]
    events = [ev for s in back.storyboard.stories for a in s.acts for g in a.groups
              for m in g.maneuvers for ev in m.events]  # fmt: skip
    assert [ev.actions[0].body for ev in events] == [
        model.storyboard.stories[0].acts[0].groups[0].maneuvers[0].events[0].actions[0].body
    ]
