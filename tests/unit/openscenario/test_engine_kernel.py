"""The compiled condition kernel: its distances are the kinematics kernel's bit for bit, its
measures the reference formulas on hand-computed cases, and a trigger with an edge and a delay
fires on the step the OpenSCENARIO semantics give."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiyari.bridge.openscenario.engine.conditions import ConditionBank, Snapshot
from hiyari.bridge.openscenario.engine.kernels import measures as M
from hiyari.bridge.openscenario.engine.kernels.snapshot import gather_entities
from hiyari.bridge.openscenario.engine.kernels.tables import (
    EntityFields,
    GatherArrays,
    WorldArrays,
)
from hiyari.bridge.openscenario.engine.motion import ActorTable
from hiyari.bridge.openscenario.engine.values import ValueStore
from hiyari.bridge.openscenario.model import (
    Condition,
    CoordinateSystem,
    DistanceType,
    Edge,
    EntityCondition,
    RelativeDistanceCondition,
    Rule,
    SpeedCondition,
    TimeHeadwayCondition,
    TimeToCollisionCondition,
)
from hiyari.kinematics import footprint_distance, footprint_extent, unrotate_xy, vehicle_to_world

#: compiled kernels against numpy formulas: CI runs these again with numpy's dispatch limited
pytestmark = pytest.mark.kernels
NO_VALUES = ValueStore({}, {}, {})  # no variables or parameters

DT = 0.1


def _fields(e: dict, k: int) -> tuple:
    """measures.entity_scalars of entity ``k`` of the arrays in ``e`` (cos and sin by numpy)."""
    c, r, h = e["centre"][k], e["ref"][k], e["heading"][k]
    return (
        c[0], c[1], r[0], r[1], h, np.cos(h), np.sin(h), e["length"][k], e["width"][k],
        e["speed"][k], 0.0, e["road_s"][k], e["road_t"][k], e["road_dir"][k],
    )  # fmt: skip


def _pair(kind: int, fs: bool, dtype: int, road: bool, e: dict) -> float:
    """pair_measure of entity 0 (A) to entity 1 (B) of the arrays in ``e``."""
    return M.pair_measure(kind, fs, dtype, road, _fields(e, 0), _fields(e, 1))


def _two_cars(gap_ahead: float, va: float, vb: float) -> dict:
    """A 4 x 2 m car A at the origin heading +x, B the same car ``gap_ahead`` m ahead
    (bumper to bumper), reference points 1.5 m behind the centres."""
    centre = np.array([[0.0, 0.0], [4.0 + gap_ahead, 0.0]])
    return {
        "centre": centre,
        "ref": centre - [1.5, 0.0],
        "heading": np.zeros(2),
        "length": np.full(2, 4.0),
        "width": np.full(2, 2.0),
        "speed": np.array([va, vb]),
        "road_s": centre[:, 0] + 100.0,
        "road_t": np.array([-1.75, -5.25]),
        "road_dir": np.ones(2),
    }


def test_pair_measures_by_hand() -> None:
    e = _two_cars(6.0, 20.0, 10.0)
    dist, hw, ttc = M.REL_DIST, M.HEADWAY, M.TTC
    assert _pair(dist, True, 1, False, e) == 6.0  # freespace: bumper to bumper
    assert _pair(dist, False, 1, False, e) == 10.0  # reference points
    assert _pair(dist, True, 0, False, e) == 6.0  # boxes' euclidean gap
    assert _pair(hw, True, 1, False, e) == pytest.approx(6.0 / 20.0)
    assert _pair(ttc, True, 1, False, e) == pytest.approx(6.0 / 10.0)
    assert _pair(ttc, False, 0, False, e) == pytest.approx(10.0 / 10.0)
    # road coordinates: 10 m along s, 3.5 m across; freespace 6 m and 1.5 m
    assert _pair(dist, False, 0, True, e) == pytest.approx(math.hypot(10.0, 3.5))
    assert _pair(dist, True, 2, True, e) == pytest.approx(1.5)
    assert _pair(hw, True, 1, True, e) == pytest.approx(6.0 / 20.0)
    # opening gap: no TTC; B behind A: no headway
    assert _pair(ttc, True, 1, False, _two_cars(6.0, 10.0, 20.0)) == math.inf
    e["centre"][1, 0] = -10.0
    assert _pair(hw, True, 1, False, e) == math.inf


def test_pair_distances_are_the_kinematics_kernels() -> None:
    """The freespace distances pair_measure gives (euclidean, longitudinal, lateral) equal
    kinematics' array functions bit for bit: the box gap is kinematics_scalar's footprint
    distance, the axis gaps its unrotate and footprint_extent, with each entity's cos and sin
    computed once (pack_entities) instead of per call."""
    rng = np.random.default_rng(7)
    n = 500
    ca, cb = rng.uniform(-8, 8, (n, 2)), rng.uniform(-8, 8, (n, 2))
    ha, hb = rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n)
    la, lb, wa, wb = (rng.uniform(0.5, 6, n) for _ in range(4))
    want = footprint_distance(ca, ha, la, wa, cb, hb, lb, wb)
    assert (want == 0).sum() > 20
    # freespace longitudinal / lateral distances in A's frame (kinematics: unrotate_xy and
    # footprint_extent), entity by entity through pair_measure
    bx, by = unrotate_xy(cb[:, 0] - ca[:, 0], cb[:, 1] - ca[:, 1], ha)
    ext_x, ext_y = footprint_extent(lb, wb, hb - ha)
    want_lon = np.maximum(0.0, np.abs(bx) - 0.5 * la - ext_x)
    want_lat = np.maximum(0.0, np.abs(by) - 0.5 * wa - ext_y)
    for k in range(n):
        e = {
            "centre": np.stack([ca[k], cb[k]]),
            "ref": np.stack([ca[k], cb[k]]),
            "heading": np.array([ha[k], hb[k]]),
            "length": np.array([la[k], lb[k]]),
            "width": np.array([wa[k], wb[k]]),
            "speed": np.zeros(2),
            "road_s": np.zeros(2),
            "road_t": np.zeros(2),
            "road_dir": np.ones(2),
        }
        assert _pair(M.REL_DIST, True, 1, False, e) == want_lon[k]
        assert _pair(M.REL_DIST, True, 2, False, e) == want_lat[k]
        assert _pair(M.REL_DIST, True, 0, False, e) == want[k]


def test_gathered_reference_points_equal_vehicle_to_world() -> None:
    rng = np.random.default_rng(2)
    xyz, h = rng.uniform(-50, 50, (6, 3)), rng.uniform(-np.pi, np.pi, 6)
    offset = rng.uniform(-2, 2, (4, 2))
    rows = np.array([3, -1, 0, 5])
    no, zero = np.zeros(4, bool), np.zeros(4)
    out = EntityFields(
        np.zeros(4, bool), np.zeros((4, 2)), np.zeros((4, 2)), zero.copy(), zero, zero,
        zero.copy(), zero.copy(), no, zero.copy(), zero.copy(), zero.copy(),
        np.zeros((4, 4), bool), no, zero.copy(),
    )  # fmt: skip
    tables = (
        WorldArrays(xyz, h, h, h),
        GatherArrays(rows, offset, no, no),
        ActorTable(4).arrays,
        out,
    )
    gather_entities(*(tuple(t) for t in tables))  # as plain tuples (see kernels.tables)
    present, centre, ref, heading = out.present, out.centre, out.ref, out.heading
    assert present.tolist() == [True, False, True, True]
    k = rows[present]
    assert np.array_equal(centre[present], xyz[k, :2])
    assert np.array_equal(ref[present], vehicle_to_world(-offset[present], xyz[k, :2], h[k]))
    assert np.array_equal(heading[present], h[k])


def _snap(t: float, speed: float) -> Snapshot:
    e = _two_cars(6.0, speed, 10.0)
    one = np.ones(2, bool)
    return Snapshot(
        t, one, e["ref"], e["centre"], e["heading"], e["length"], e["width"], e["speed"],
        np.zeros(2), one, e["road_s"], e["road_t"], e["road_dir"], set(), np.zeros(2, bool),
    )  # fmt: skip


def _fired_steps(conditions: list[Condition], speed: list[float]) -> list[int]:
    bank = ConditionBank([((c,),) for c in conditions], {"a": 0, "b": 1}, lambda *a: 0, NO_VALUES,
                         lambda p: None, DT)  # fmt: skip
    none = np.zeros(0, np.int8)
    out = []
    for k, v in enumerate(speed):
        fired = bank.evaluate(_snap(k * DT, v), np.ones(len(conditions), bool), none, none)
        out += [(k, i) for i in np.flatnonzero(fired).tolist()]
    return out


def test_entity_triggers_with_edges_and_delays_fire_on_their_step() -> None:
    """A's speed ramps 0, 2, 4, ... m/s behind B (10 m/s, 6 m ahead): speed > 7 holds from
    step 4 (8 m/s), TTC < 1.5 s (6 / (v - 10)) from step 8 (6 / 6 = 1.0 s; at step 7 it is
    6 / 4 = 1.5, not less), headway < 0.5 s (6 / v) from step 7 (6 / 14 = 0.43)."""
    ramp = [2.0 * k for k in range(14)]

    def cond(body: object, edge: Edge, delay: float = 0.0) -> Condition:
        return Condition("c", EntityCondition(("a",), "any", body), edge, delay)

    speed = SpeedCondition(7.0, Rule.GREATER_THAN)
    ttc = TimeToCollisionCondition(1.5, True, Rule.LESS_THAN, entity="b",
                                   distance_type=DistanceType.LONGITUDINAL)  # fmt: skip
    hw = TimeHeadwayCondition("b", 0.5, True, Rule.LESS_THAN, CoordinateSystem.ROAD,
                              DistanceType.LONGITUDINAL)  # fmt: skip
    gap = RelativeDistanceCondition("b", DistanceType.LONGITUDINAL, 6.0, True, Rule.EQUAL_TO)
    fired = _fired_steps(
        [
            cond(speed, Edge.RISING),
            cond(speed, Edge.RISING, delay=0.3),
            cond(ttc, Edge.RISING, delay=0.2),
            cond(hw, Edge.RISING),
            cond(gap, Edge.FALLING),
            cond(speed, Edge.NONE, delay=0.5),
        ],
        ramp,
    )
    assert [k for k, i in fired if i == 0] == [4]
    assert [k for k, i in fired if i == 1] == [7]
    assert [k for k, i in fired if i == 2] == [10]
    assert [k for k, i in fired if i == 3] == [7]
    assert [k for k, i in fired if i == 4] == []  # the gap never changes
    assert [k for k, i in fired if i == 5] == list(range(9, 14))


def test_ttc_bound_decides_only_when_the_footprint_ttc_is_above_the_value() -> None:
    """The kernel skips the footprint distance of a freespace euclidean TTC row when the
    centres' distance less the half-diagonals already puts the TTC above the value: wherever
    that bound says so, the exact TTC is above the value (so every rule decides as for an
    infinite TTC), and the bound decides a good share of random cases, not all."""
    rng = np.random.default_rng(7)
    decided = 0
    n = 4000
    for _ in range(n):
        centre = rng.uniform(-40, 40, (2, 2)) + rng.uniform(-1e5, 1e5, 2)  # far from 0
        h = rng.uniform(-np.pi, np.pi, 2)
        length, width = rng.uniform(0.5, 12.0, 2), rng.uniform(0.5, 3.0, 2)
        speed = rng.uniform(0.0, 40.0, 2)
        value = float(rng.uniform(-1.0, 6.0))
        e = {"centre": centre, "ref": centre, "heading": h, "length": length, "width": width,
             "speed": speed, "road_s": np.zeros(2), "road_t": np.zeros(2), "road_dir": np.ones(2)}  # fmt: skip
        if not M.ttc_above(value, _fields(e, 0), _fields(e, 1)):
            continue
        decided += 1
        ttc = _pair(M.TTC, True, 0, False, e)
        assert ttc > value
        for rule in range(6):
            assert M.holds(ttc, value, rule) == M.holds(math.inf, value, rule)
    assert 0.2 * n < decided < 0.95 * n
