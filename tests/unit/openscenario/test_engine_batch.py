"""The engine's batched condition evaluation equals one-condition-at-a-time evaluation, and the
kernel's rectangle-to-rectangle distance it uses, against hand-computed values and shapely."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from openscenario_files import ALKS

from hiyari.bridge.openscenario.engine.conditions import ConditionBank, Snapshot
from hiyari.bridge.openscenario.engine.kernels import motion_kernel as MK
from hiyari.bridge.openscenario.engine.kernels.snapshot import (
    F_ACCEL,
    F_HEADING,
    F_ROAD_CODE,
    F_ROAD_DIR,
    F_ROAD_S,
    F_ROAD_T,
    F_SPEED,
    gather_entities,
)
from hiyari.bridge.openscenario.engine.kernels.tables import (
    EntityFields,
    GatherArrays,
    WorldArrays,
)
from hiyari.bridge.openscenario.engine.motion import ActorTable
from hiyari.bridge.openscenario.engine.positions import Pose
from hiyari.bridge.openscenario.engine.values import ValueStore
from hiyari.bridge.openscenario.model import (
    Condition,
    CoordinateSystem,
    DistanceType,
    Edge,
    EntityCondition,
    RelativeDistanceCondition,
    Rule,
    TimeHeadwayCondition,
    TimeToCollisionCondition,
)
from hiyari.bridge.openscenario.model.conditions import (
    AccelerationCondition,
    DistanceCondition,
    ReachPositionCondition,
    RelativeSpeedCondition,
    SpeedCondition,
    StandStillCondition,
)
from hiyari.bridge.openscenario.model.positions import WorldPosition
from hiyari.kinematics import footprint_corners, footprint_distance
from hiyari.net.road.opendrive_lanes import OpenDriveMap

NO_VALUES = ValueStore({}, {}, {})  # no variables or parameters

E, DT = 6, 0.1


def test_footprint_distance_by_hand() -> None:
    o = np.zeros(2)
    # 4 x 2 boxes: 6 m bumper to bumper; corner to corner (1, 1) apart; crossed planks touch
    assert footprint_distance(o, 0.0, 4.0, 2.0, np.array([10.0, 0.0]), 0.0, 4.0, 2.0) == 6.0
    d = footprint_distance(o, 0.0, 4.0, 2.0, np.array([5.0, 3.0]), 0.0, 4.0, 2.0)
    assert d == pytest.approx(math.sqrt(2.0))
    assert footprint_distance(o, 0.0, 10.0, 1.0, o, math.pi / 2, 10.0, 1.0) == 0.0
    # a 2 x 2 square turned 45 deg, its tip sqrt(2) ahead of its centre: 2 m from A's front
    d = footprint_distance(o, 0.0, 2.0, 2.0, np.array([3.0 + math.sqrt(2.0), 0.0]), math.pi / 4,
                           2.0, 2.0)  # fmt: skip
    assert d == pytest.approx(2.0)
    # the same pair seen from B (symmetric), and B ahead of a north-facing A
    d = footprint_distance(np.array([3.0 + math.sqrt(2.0), 0.0]), math.pi / 4, 2.0, 2.0, o, 0.0,
                           2.0, 2.0)  # fmt: skip
    assert d == pytest.approx(2.0)
    d = footprint_distance(o, math.pi / 2, 4.0, 2.0, np.array([0.0, 9.0]), 0.0, 4.0, 2.0)
    assert d == pytest.approx(9.0 - 2.0 - 1.0)


def test_footprint_distance_matches_shapely_on_random_boxes() -> None:
    rng = np.random.default_rng(3)
    n = 400
    ca, cb = rng.uniform(-8, 8, (n, 2)), rng.uniform(-8, 8, (n, 2))
    ha, hb = rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n)
    la, lb, wa, wb = (rng.uniform(0.5, 6, n) for _ in range(4))
    got = footprint_distance(ca, ha, la, wa, cb, hb, lb, wb)
    pa = shapely.polygons(footprint_corners(ca, ha, la, wa))
    pb = shapely.polygons(footprint_corners(cb, hb, lb, wb))
    want = shapely.distance(pa, pb)
    assert np.allclose(got, want, atol=1e-9)
    assert (got == 0).sum() > 20 and (got > 1).sum() > 100  # both cases covered


def _snapshot(rng: np.random.Generator, t: float) -> Snapshot:
    h = rng.uniform(-np.pi, np.pi, E)
    centre = rng.uniform(-15, 15, (E, 2))
    ref = centre - 1.4 * np.stack([np.cos(h), np.sin(h)], 1)
    speed = np.where(rng.random(E) < 0.3, 0.0, rng.uniform(0, 20, E))
    return Snapshot(
        time=t,
        present=rng.random(E) < 0.75,
        ref=ref,
        centre=centre,
        heading=h,
        length=rng.uniform(3, 6, E),
        width=rng.uniform(1.5, 2.5, E),
        speed=speed,
        accel=rng.uniform(-5, 3, E),
        on_net=np.ones(E, bool),
        road_s=rng.uniform(0, 60, E),
        road_t=rng.uniform(-6, 6, E),
        road_dir=np.where(rng.random(E) < 0.5, 1.0, -1.0),
        contacts=set(),
        contact_any=np.zeros(E, bool),
    )


def _random_conditions(rng: np.random.Generator, n: int) -> list[Condition]:
    rules, names = list(Rule), [f"e{k}" for k in range(E)]
    out = []
    for k in range(n):
        rule = rules[rng.integers(len(rules))]
        other = names[rng.integers(E)]
        fs = bool(rng.random() < 0.5)
        dtype = list(DistanceType)[rng.integers(3)]
        cs = CoordinateSystem.ROAD if rng.random() < 0.3 else CoordinateSystem.ENTITY
        point = WorldPosition(*rng.uniform(-15, 15, 2))
        body = [
            RelativeDistanceCondition(other, dtype, rng.uniform(0, 20), fs, rule, cs),
            TimeHeadwayCondition(other, rng.uniform(0, 3), fs, rule, cs, dtype),
            TimeToCollisionCondition(
                rng.uniform(0, 4), fs, rule, entity=other, distance_type=dtype
            ),  # fmt: skip
            TimeToCollisionCondition(rng.uniform(0, 4), fs, rule, position=point),
            SpeedCondition(rng.uniform(0, 20), rule),
            AccelerationCondition(rng.uniform(-5, 3), rule),
            RelativeSpeedCondition(other, rng.uniform(-10, 10), rule),
            StandStillCondition(rng.uniform(0, 0.3)),
            DistanceCondition(point, DistanceType.EUCLIDEAN, rng.uniform(0, 20), fs, rule),
            ReachPositionCondition(point, rng.uniform(0, 15)),
        ][k % 10]
        triggering = tuple(rng.choice(names, size=int(rng.integers(1, 3)), replace=False))
        ec = EntityCondition(triggering, "all" if rng.random() < 0.3 else "any", body)
        out.append(Condition(f"c{k}", ec, Edge.NONE))
    return out


def test_batched_evaluation_equals_one_condition_at_a_time() -> None:
    """All conditions in one bank (each its own trigger, a random half of them active per
    step) give the same firings as one bank per condition fed the same states."""
    rng = np.random.default_rng(11)
    conditions = _random_conditions(rng, 120)
    index = {f"e{k}": k for k in range(E)}

    def resolve(p: WorldPosition) -> Pose:
        return Pose(p.x, p.y, 0.0, 0.0, "", 0, 0.0, 0.0)

    def bank(conds: list[Condition]) -> ConditionBank:
        return ConditionBank([((c,),) for c in conds], index, lambda *a: 0, NO_VALUES, resolve, DT)

    batched, singles = bank(conditions), [bank([c]) for c in conditions]
    none = np.zeros(0, np.int8)
    fired_any = np.zeros(len(conditions), bool)
    fired_not = np.zeros(len(conditions), bool)
    for step in range(12):
        snap = _snapshot(rng, step * DT)
        active = rng.random(len(conditions)) < 0.6
        got = batched.evaluate(snap, active, none, none)
        want = [s.evaluate(snap, active[k : k + 1], none, none)[0] for k, s in enumerate(singles)]
        assert got.tolist() == want
        # nothing is measured on absent entities: no rule holds (not even notEqualTo)
        absent = [not snap.present[[index[n] for n in c.body.triggering]].any() for c in conditions]
        assert not (got & np.array(absent)).any()
        fired_any |= got
        fired_not |= active & ~got
    assert fired_any.sum() > 30 and fired_not.sum() > 30  # not all one way


def _gathered_snapshot(t: float, length: np.ndarray, width: np.ndarray) -> tuple:
    """A Snapshot on zeroed arrays for gather_entities to fill, and those arrays as its
    EntityFields."""
    present, centre, ref, ent = (
        np.zeros(E, bool),
        np.zeros((E, 2)),
        np.zeros((E, 2)),
        np.zeros((7, E)),
    )
    on_net, contact_any = np.ones(E, bool), np.zeros(E, bool)
    snap = Snapshot(
        t, present, ref, centre, ent[F_HEADING], length, width, ent[F_SPEED], ent[F_ACCEL],
        on_net, ent[F_ROAD_S], ent[F_ROAD_T], ent[F_ROAD_DIR], set(), contact_any,
        ent[F_ROAD_CODE],
    )  # fmt: skip
    fields = EntityFields(
        present, centre, ref, ent[F_HEADING], length, width, ent[F_SPEED], ent[F_ACCEL],
        on_net, ent[F_ROAD_S], ent[F_ROAD_T], ent[F_ROAD_DIR], np.zeros((E, E), bool),
        contact_any, ent[F_ROAD_CODE],
    )  # fmt: skip
    return snap, fields


def test_gathering_in_the_trigger_call_equals_gathering_first() -> None:
    """The snapshot gathered in the trigger evaluation's compiled call (with point conditions:
    just before it, as their positions need it) is the one gather_entities fills, and the
    firings and their count are those of evaluating after it, bit for bit."""
    rng = np.random.default_rng(5)
    index = {f"e{k}": k for k in range(E)}

    def resolve(p: WorldPosition) -> Pose:
        return Pose(p.x, p.y, 0.0, 0.0, "", 0, 0.0, 0.0)

    conditions = _random_conditions(rng, 60)
    no_points = [c for k, c in enumerate(conditions) if k % 10 not in (3, 8, 9)]
    length, width, none = rng.uniform(3, 6, E), rng.uniform(1.5, 2.5, E), np.zeros(0, np.int8)
    fired_total = 0
    for conds in (no_points, conditions):
        banks = [
            ConditionBank([((c,),) for c in conds], index, lambda *a: 0, NO_VALUES, resolve, DT)
            for _ in range(2)
        ]
        for step in range(10):
            n_world = E + 2
            rows = rng.permutation(n_world)[:E]
            rows[rng.random(E) < 0.25] = -1
            world = WorldArrays(
                rng.uniform(-15, 15, (n_world, 3)), rng.uniform(-np.pi, np.pi, n_world),
                rng.uniform(0, 20, n_world), rng.uniform(-5, 3, n_world),
            )  # fmt: skip
            where = GatherArrays(
                rows, rng.uniform(-1, 2, (E, 2)), rng.random(E) < 0.5, np.zeros(E, bool)
            )
            actors = ActorTable(E).arrays._replace(
                road_code=rng.integers(-1, 2, E), state=rng.uniform(0, 60, (len(MK.STATE), E)),
                direction=rng.choice([-1.0, 1.0], E),
            )  # fmt: skip
            active = rng.random(len(conds)) < 0.7
            (snap0, out0), (snap1, out1) = (_gathered_snapshot(step * DT, length, width)
                                            for _ in range(2))  # fmt: skip
            gather = (tuple(world), tuple(where), tuple(actors))  # as the kernels take them
            gather_entities(*gather, tuple(out0))
            want = banks[0].evaluate(snap0, active, none, none).copy()
            got = banks[1].evaluate(snap1, active, none, none, gather)
            assert got.tolist() == want.tolist()
            assert banks[1].n_fired == banks[0].n_fired == int(want.sum())
            assert all(
                np.array_equal(a, b, equal_nan=True) for a, b in zip(out0, out1, strict=True)
            )
            fired_total += int(want.sum())
    assert fired_total > 20  # the comparison saw firings


def test_locate_near_matches_the_full_search_on_a_curved_road() -> None:
    """Re-locating an actor from its s one step earlier (Newton only) gives the road
    coordinates of the nearest-sample search, on a road of changing curvature."""
    odr = OpenDriveMap.from_file(ALKS / "road_networks/alks_road_different_curvatures.xodr")
    road = next(iter(odr.roads))
    rng = np.random.default_rng(5)
    s = rng.uniform(10.0, odr.road(road).length - 10.0, 40)
    t = rng.uniform(-9.0, 9.0, 40)
    x, y, _, _ = odr.road_pose(road, s, t)
    for k in range(40):
        want = odr.locate(x[k : k + 1], y[k : k + 1], road)[0]
        got = odr.locate_near(road, x[k], y[k], s[k] - 1.5)  # about one step behind at 30 m/s
        assert got.road == want.road and got.lane == want.lane
        assert got.s == pytest.approx(s[k], abs=1e-6) and got.s == pytest.approx(want.s, abs=1e-6)
        assert got.t == pytest.approx(t[k], abs=1e-6)
