"""Distances and walks along the road links (engine.frames.links), by hand on a small graph:
road A (100 m) whose end meets road B's end (50 m, so B is driven towards decreasing s after
A), and road C (40 m) after A's start; the trigger kernel's road-frame translation
(measures.in_road_of)."""

from __future__ import annotations

import math

import numpy as np

from hiyari.bridge.openscenario.engine.frames.links import road_ahead, walk
from hiyari.bridge.openscenario.engine.kernels import measures as M
from hiyari.net.road.topology import RoadGraph

GRAPH = RoadGraph(
    {"A": 100.0, "B": 50.0, "C": 40.0},
    {
        ("A", 1): (("B", -1),),
        ("B", 1): (("A", -1),),
        ("A", -1): (("C", -1),),
        ("C", 1): (("A", 1),),
    },
)


def test_walk_turns_the_direction_where_a_road_is_entered_at_its_end() -> None:
    # 10 m to A's end, 20 m into B from its end: s = 30, travelling towards decreasing s
    assert walk(GRAPH, "A", 90.0, 1, 30.0) == ("B", 30.0, -1)
    # backwards from there: the same way back
    assert walk(GRAPH, "B", 30.0, -1, -30.0) == ("A", 90.0, 1)
    # backwards past A's start into C (entered at its end, same direction of travel)
    assert walk(GRAPH, "A", 5.0, 1, -15.0) == ("C", 30.0, 1)
    # a road end with no link: it stops there
    assert walk(GRAPH, "C", 10.0, 1, -25.0) == ("C", 0.0, 1)


def test_road_ahead_is_signed_along_the_travel_direction() -> None:
    assert road_ahead(GRAPH, "A", 90.0, 1, "B", 30.0) == 30.0
    assert road_ahead(GRAPH, "B", 30.0, -1, "A", 90.0) == -30.0
    assert road_ahead(GRAPH, "A", 5.0, 1, "C", 30.0) == -15.0
    assert road_ahead(GRAPH, "A", 10.0, -1, "A", 4.0) == 6.0
    lone = RoadGraph({"A": 100.0, "D": 10.0}, {})
    assert math.isnan(road_ahead(lone, "A", 5.0, 1, "D", 1.0))


def test_in_road_of_expresses_the_other_road_point_on_ones_own() -> None:
    """Road b (code 1) entered at its end from road a (code 0): b's s = 30 lies
    shift + sign * 30 = 150 - 30 = 120 along a's s, its t and direction turned; unlinked
    roads give NaN."""

    def fields(s: float, t: float, d: float, road: float) -> tuple:
        f = [0.0] * M.N_FIELDS
        f[M.E_S], f[M.E_T], f[M.E_DIR], f[M.E_ROAD] = s, t, d, road
        return tuple(f)

    links = np.full((3, 3, 2), np.nan)
    links[0, 1] = 150.0, -1.0
    a, b = fields(90.0, -2.0, 1.0, 0.0), fields(30.0, 2.0, -1.0, 1.0)
    moved = M.in_road_of(a, b, links)
    assert (moved[M.E_S], moved[M.E_T], moved[M.E_DIR], moved[M.E_ROAD]) == (120.0, -2.0, 1.0, 0.0)
    assert M.in_road_of(a, fields(5.0, 0.0, 1.0, 0.0), links)[M.E_S] == 5.0  # same road
    assert math.isnan(M.in_road_of(a, fields(5.0, 0.0, 1.0, 2.0), links)[M.E_S])
