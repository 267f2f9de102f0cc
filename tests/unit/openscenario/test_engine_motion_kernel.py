"""The scenario engine's compiled motion: lane centre lines (LaneProfile), line / arc
reference lines (PlanView), transitions, placement and command assembly, each against the
numpy formulas they replace (bit for bit) or hand-computed values."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from paths import SHARED

from hiyari.bridge.openscenario.engine.kernels import motion_kernel as MK
from hiyari.bridge.openscenario.engine.kernels.command_kernel import (
    advance_and_command,
    command_rows,
    command_step,
    lane_keys,
)
from hiyari.bridge.openscenario.engine.kernels.shapes import CUBIC, LINEAR, SINUSOIDAL
from hiyari.bridge.openscenario.engine.kernels.tables import (
    ActorArrays,
    CommandArrays,
    LaneArrays,
    RoadArrays,
)
from hiyari.kinematics import point_ahead, vehicle_to_world
from hiyari.net.road.lane_profile import lane_profile
from hiyari.net.road.opendrive_lanes import LaneSection, LaneSpec, OpenDriveMap, Poly3
from hiyari.net.road.plan_view import road_pose_at
from hiyari.traffic.commands import heading_to_sumo_angle

#: compiled kernels against numpy formulas: CI runs these again with numpy's dispatch limited
pytestmark = pytest.mark.kernels

ROADS = SHARED / "data/openscenario/alks/road_networks"
CURVED = ROADS / "alks_road_different_curvatures.xodr"
ARC = ROADS / "alks_road_right_radius_250m.xodr"


def _piecewise(records: tuple[Poly3, ...], s: np.ndarray) -> np.ndarray:
    """The numpy evaluation of piecewise cubics the compiled one replaced."""
    if not records:
        return np.zeros_like(s)
    starts = np.array([r.s0 for r in records])
    k = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(records) - 1)
    out = np.empty_like(s)
    for i in np.unique(k):
        r, m = records[i], k == i
        ds = s[m] - r.s0
        out[m] = r.a + ds * (r.b + ds * (r.c + ds * r.d))
    return out


def _numpy_lane_centre(road: object, lane: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    t, width = _piecewise(road.lane_offset, s), np.zeros_like(s)
    starts = np.array([sec.s0 for sec in road.sections])
    k = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(starts) - 1)
    side = 1 if lane > 0 else -1
    for i, sec in enumerate(road.sections):
        m = k == i
        ws = [_piecewise(sec.lanes[side * j].widths, s[m] - sec.s0) for j in range(1, abs(lane))]
        w = _piecewise(sec.lanes[lane].widths, s[m] - sec.s0)
        t[m] += side * (sum(ws) + 0.5 * w)
        width[m] = w
    return t, width


@pytest.fixture(scope="module")
def curved_road() -> object:
    """The curved ALKS road with three lane sections, varying widths and a lane offset."""
    road = OpenDriveMap.from_file(CURVED).road("0")
    base = road.sections[0].lanes
    sections = []
    for i, (s0, s1) in enumerate(((0.0, 300.0), (300.0, 900.0), (900.0, road.length))):
        lanes = {}
        for lid, spec in base.items():
            w = (
                Poly3(0.0, 3.5 + 0.1 * i, 1e-3 * lid, -2e-6, 1e-9),
                Poly3(150.0, 3.6, 0.0, 1e-6, 0.0),
            )
            lanes[lid] = LaneSpec(lid, spec.type, () if lid == 0 else w)
        sections.append(LaneSection(i, s0, s1, lanes))
    offset = (Poly3(0.0, 0.2, 1e-3, 0.0, -1e-9), Poly3(500.0, -0.3, 0.0, 2e-6, 0.0))
    return dataclasses.replace(road, sections=tuple(sections), lane_offset=offset)


def test_lane_centres_equal_the_numpy_evaluation(curved_road: object) -> None:
    s = np.linspace(-5.0, curved_road.length + 5.0, 4001)
    for lane in (-3, -2, -1, 1, 2, 3):
        want_t, want_w = _numpy_lane_centre(curved_road, lane, s)
        t, w = curved_road.lane_centre_t(lane, s)
        assert np.array_equal(t, want_t) and np.array_equal(w, want_w)
        assert np.max(np.abs(t - want_t)) <= 1e-9
        for i in range(0, len(s), 97):
            assert curved_road.lane_t(lane, float(s[i])) == want_t[i]
    # the engine's profile of several roads indexes each road's own records
    other = OpenDriveMap.from_file(ARC).road("0")
    prof = lane_profile([other, curved_road]).arrays()
    t, _, missing = MK.lane_centre_at(*prof, 1, -2, 640.0)
    assert missing == -1 and t == curved_road.lane_centre_t(-2, np.array([640.0]))[0][0]
    # no lane -9 in its second section: index 2 of the profile (the first road has one)
    assert MK.lane_centre_at(*prof, 1, -9, 640.0)[2] == 2


def _numpy_road_pose(road: object, s: np.ndarray, t: np.ndarray) -> tuple:
    """Road.reference + road_pose as numpy evaluated lines and arcs."""
    sc = np.clip(s, 0.0, road.length)
    starts = np.array([g.s0 for g in road.geometries])
    k = np.clip(np.searchsorted(starts, sc, side="right") - 1, 0, len(starts) - 1)
    x, y, h = np.empty_like(s), np.empty_like(s), np.empty_like(s)
    for i in np.unique(k):
        g, m = road.geometries[i], k == i
        u = sc[m] - g.s0
        if g.kind == "line":
            x[m], y[m], h[m] = g.x + u * math.cos(g.hdg), g.y + u * math.sin(g.hdg), g.hdg
        else:
            (kk,) = g.params
            hh = g.hdg + kk * u
            x[m] = g.x + (np.sin(hh) - math.sin(g.hdg)) / kk
            y[m] = g.y - (np.cos(hh) - math.cos(g.hdg)) / kk
            h[m] = hh
    return x - t * np.sin(h), y + t * np.cos(h), h


def test_line_and_arc_poses_equal_the_numpy_evaluation() -> None:
    odr = OpenDriveMap.from_file(ARC)
    road = odr.road("0")
    s = np.linspace(-3.0, road.length + 3.0, 2001)
    t = np.linspace(-9.0, 9.0, len(s))
    want = _numpy_road_pose(road, s, t)
    got = odr.road_pose("0", s, t)
    assert all(np.array_equal(a, b) for a, b in zip(want, (got[0], got[1], got[3]), strict=True))
    plan = road.plan_view.arrays()
    for i in range(0, len(s), 50):
        x, y, z, h = road_pose_at(*plan, s[i], t[i])
        assert (x, y, z, h) == (want[0][i], want[1][i], 0.0, want[2][i])
    assert OpenDriveMap.from_file(CURVED).road("0").plan_view is None  # spirals: numpy path


def _actors(st: np.ndarray, **given: np.ndarray) -> ActorArrays:
    """The ActorArrays of state matrix ``st`` (a column per actor): off the roads, heading
    towards increasing s on straight lines, no transition running; but for the ``given``
    arrays."""
    n = st.shape[1]
    no = np.zeros(n, bool)
    base = {
        "state": st, "direction": np.ones(n), "kappa": np.zeros(n),
        "road_code": np.full(n, -1, np.intp), "lane": np.zeros(n, np.int64), "free": no,
        "has_long": no, "long_par": np.zeros((n, 8)), "long_done": no.copy(), "has_lat": no,
        "lat_par": np.zeros((n, 9)), "lat_done": no.copy(),
    }  # fmt: skip
    return ActorArrays(**(base | given))


def _lanes(roads: list) -> LaneArrays:
    return LaneArrays(*lane_profile(roads).arrays())


def _plain(*tables: tuple) -> tuple[tuple, ...]:
    """The tables as plain tuples, as the kernels take them (see kernels.tables)."""
    return tuple(tuple(t) for t in tables)


def _long_row(v0: float, goal: float, shape: int, span: float, t0: float = 0.0) -> np.ndarray:
    row = np.zeros(8)
    row[[MK.L_V0, MK.L_GOAL, MK.L_SHAPE, MK.L_SPAN, MK.L_T0]] = v0, goal, shape, span, t0
    return row


def _advance(long_par: np.ndarray, now: float, dt: float, v: float) -> tuple[float, float, bool]:
    """(v, s, done) of one row starting at s = 0 after one step."""
    st = np.zeros((len(MK.STATE), 1))
    st[MK.V, 0] = v
    actors = _actors(st, has_long=np.ones(1, dtype=bool), long_par=long_par[None])
    MK.advance_long(np.array([0]), now, dt, tuple(actors))
    return float(st[MK.V, 0]), float(st[MK.S, 0]), bool(actors.long_done[0])


def test_speed_transitions_follow_their_shapes() -> None:
    # linear 10 -> 20 m/s over 2 s, at 1 s: 15 m/s; s by the trapezoid over the step
    v, s, done = _advance(_long_row(10.0, 20.0, LINEAR, 2.0), 1.0, 0.1, 14.5)
    assert (v, done) == (15.0, False) and s == pytest.approx(0.5 * (14.5 + 15.0) * 0.1)
    v, _, _ = _advance(_long_row(10.0, 20.0, CUBIC, 2.0), 1.0, 0.1, 14.0)
    assert v == pytest.approx(15.0)  # cubic at half way: half the change
    v, _, _ = _advance(_long_row(10.0, 20.0, SINUSOIDAL, 2.0), 0.5, 0.1, 10.0)
    assert v == pytest.approx(10.0 + 10.0 * 0.5 * (1 - math.cos(math.pi / 4)))
    # ends 0.04 s into a 0.1 s step: ramps 0.04 s, then 0.06 s at the goal
    v, s, done = _advance(_long_row(10.0, 20.0, LINEAR, 2.0), 2.06, 0.1, 19.8)
    assert (v, done) == (20.0, True)
    assert s == pytest.approx(0.5 * (19.8 + 20.0) * 0.04 + 20.0 * 0.06)


def test_lateral_transition_reaches_the_target_lane(curved_road: object) -> None:
    lanes = _lanes([curved_road])
    target = curved_road.lane_t(-2, 400.0)
    t0 = curved_road.lane_t(-1, 400.0)
    row = np.zeros(9)
    row[[MK.T_T0, MK.T_SHAPE, MK.T_SPAN, MK.T_LANE, MK.T_OFFSET]] = t0, SINUSOIDAL, 4.0, -2, 0.25
    st = np.zeros((len(MK.STATE), 1))
    st[MK.S, 0], st[MK.T, 0] = 400.0, t0
    actors = _actors(st, has_lat=np.ones(1, dtype=bool), lat_par=row[None, :])
    done = actors.lat_done
    for now, want_done in ((2.0, False), (4.0, True)):
        missing, n_done = MK.advance_lat(np.array([0]), now, 0.05, *_plain(actors, lanes))
        assert missing == -1 and bool(done[0]) == want_done and n_done == int(want_done)
        frac = 0.5 if now == 2.0 else 1.0
        assert st[MK.T, 0] == pytest.approx(t0 + (target + 0.25 - t0) * frac)


def test_placement_and_commands_equal_the_numpy_formulas() -> None:
    rng = np.random.default_rng(3)
    a, b = rng.uniform(-20, 20, 500), rng.choice([-2 * math.pi, 2 * math.pi, 1.5], 500)
    assert all(MK._remainder(x, y) == np.remainder(x, y) for x, y in zip(a, b, strict=True))
    n = 40
    rows = np.arange(n)[::-1].copy()
    x, y, h = rng.uniform(-100, 100, n), rng.uniform(-100, 100, n), rng.uniform(-4, 4, n)
    v, v_lat = rng.uniform(0, 30, n), rng.uniform(-2, 2, n)
    v_lat[::3], v[::7] = 0.0, -v[::7]  # not sliding (the short cuts), reversing
    v_lat[1::6] = -0.0
    cx, cy = rng.uniform(0, 2, n), rng.uniform(-0.5, 0.5, n)
    # the speed along the path: the lateral speed counts only when it alone is faster
    path_speed = np.where(v_lat == 0.0, np.abs(v), np.maximum(np.abs(v), np.abs(v_lat)))
    sent = path_speed.copy()
    sent[::2] = np.nan
    st = np.zeros((len(MK.STATE), n))
    st[MK.X], st[MK.Y], st[MK.H], st[MK.V], st[MK.V_LAT] = x, y, h, v, v_lat
    centres, heading, send, sumo = np.zeros((n, 2)), np.zeros(n), np.zeros(n), np.zeros((3, n))
    length = rng.uniform(0.5, 15.0, n)
    key = np.zeros((n, 3), np.int64)
    cmd = CommandArrays(rows, cx, cy, length, sent.copy(), key, centres, heading, send, sumo)
    command_rows(*_plain(cmd, _actors(st)))
    want = vehicle_to_world(np.stack([cx, cy], 1)[rows], np.stack([x, y], 1)[rows], h[rows])
    assert np.array_equal(centres, want) and np.array_equal(heading, h[rows])
    # what SUMO is told: the front bumper and SUMO angle, as move_vehicle computes them
    front = point_ahead(want, h[rows], 0.5 * length[rows])
    assert np.array_equal(sumo[:2].T, front)
    assert np.array_equal(sumo[2], np.mod(90.0 - np.degrees(h[rows]), 360.0))
    assert sumo[2].tolist() == [heading_to_sumo_angle(float(x)) for x in h[rows]]
    speed = path_speed[rows]
    assert np.array_equal(send, np.where(rows % 2 == 1, np.nan, speed), equal_nan=True)
    # placement: heading from the reference line, direction, slip and relative heading
    direction = rng.choice([-1.0, 1.0], n)
    h_rel = rng.uniform(-0.1, 0.1, n)
    st[MK.H_REL] = h_rel
    px, py, pz, h_ref = x[rows] + 1.0, y[rows], np.zeros(n), h[rows]
    MK.place_posed(rows, px, py, pz, h_ref, tuple(_actors(st, direction=direction)))
    lat = direction * v_lat  # the speed is along the path: the lane's share is the rest
    along = np.copysign(np.sqrt(np.maximum(0.0, v * v - lat * lat)), v)
    slip = np.where(np.abs(v) > 1e-6, np.arctan2(lat, along), 0.0)[rows]
    hh = h_ref + np.where(direction[rows] > 0, 0.0, np.pi) + slip + h_rel[rows]
    assert np.array_equal(st[MK.H][rows], np.remainder(hh + np.pi, 2 * np.pi) - np.pi)
    assert np.array_equal(st[MK.X][rows], px)


def test_lane_keys_flag_road_lane_and_section_changes(curved_road: object) -> None:
    lanes = _lanes([curved_road])
    rows = np.array([0, 1])
    st = np.zeros((len(MK.STATE), 2))
    lane = np.array([-1, -2])
    actors = _actors(st, road_code=np.zeros(2, dtype=np.intp), lane=lane)
    key = np.full((2, 3), -2, dtype=np.int64)
    out = (np.zeros((2, 2)), np.zeros(2), np.zeros(2), np.zeros((3, 2)))
    cmd = CommandArrays(rows, np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2), key, *out)

    def changed(s: list[float]) -> list[int]:
        st[MK.S] = s
        return lane_keys(*_plain(cmd, actors, lanes)).tolist()

    assert changed([10.0, 20.0]) == [0, 1] and key[:, 2].tolist() == [0, 0]
    assert changed([11.0, 299.0]) == []
    assert changed([11.0, 301.0]) == [1] and key[1, 2] == 1  # into the second section
    lane[0] = -2
    assert changed([11.0, 301.0]) == [0]


def test_advance_and_place_equals_the_passes_one_by_one() -> None:
    """The one-call step (speeds, lateral positions, placement) leaves the same table, bit
    for bit, as the three passes called one after the other; a lateral transition ending
    leaves the rows unplaced (the caller updates their lanes first)."""
    rng = np.random.default_rng(11)
    road = OpenDriveMap.from_file(ROADS / "alks_road_left_radius_250m.xodr").road("0")
    lanes, plan = _lanes([road]), RoadArrays(*road.plan_view.arrays())
    n = 8
    rows = np.arange(n)
    st = np.zeros((len(MK.STATE), n))
    st[MK.S] = rng.uniform(50.0, 250.0, n)
    st[MK.T] = [road.lane_t(-1, s) for s in st[MK.S]]
    st[MK.V] = rng.uniform(5.0, 30.0, n)
    has_long, has_lat = rng.random(n) < 0.6, rng.random(n) < 0.6
    long_par, lat_par = np.zeros((n, 8)), np.zeros((n, 9))
    long_par[:, MK.L_V0], long_par[:, MK.L_GOAL] = st[MK.V], rng.uniform(0.0, 30.0, n)
    long_par[:, MK.L_SHAPE], long_par[:, MK.L_SPAN] = LINEAR, rng.uniform(0.5, 3.0, n)
    lat_par[:, MK.T_T0], lat_par[:, MK.T_SHAPE], lat_par[:, MK.T_LANE] = st[MK.T], SINUSOIDAL, -2
    lat_par[:, MK.T_SPAN] = rng.uniform(2.0, 5.0, n)
    kappa, direction = rng.uniform(-1e-3, 1e-3, n), np.ones(n)
    for now, want_placed in ((1.0, True), (6.0, False)):
        one, two = (
            _actors(
                st.copy(), kappa=kappa, direction=direction, has_long=has_long,
                long_par=long_par.copy(), has_lat=has_lat, lat_par=lat_par.copy(),
            )
            for _ in range(2)
        )  # fmt: skip
        got = MK.advance_and_place(rows, now, 0.05, True, *_plain(one, lanes, plan))
        n_long = MK.advance_long(rows, now, 0.05, tuple(two))
        missing, n_lat = MK.advance_lat(rows, now, 0.05, *_plain(two, lanes))
        if want_placed:
            MK.place_rows(rows, *_plain(plan, two))
        assert got == (n_long, missing, n_lat, want_placed)
        assert all(np.array_equal(a, b) for a, b in zip(one, two, strict=True))


def test_advance_and_command_commands_only_when_nothing_ended() -> None:
    """The motion step and the commands in one call leave the same arrays, bit for bit, as
    advance_and_place then command_step; when a transition ends (the storyboard ends its
    action first) the commands are left to the caller, their arrays untouched."""
    rng = np.random.default_rng(5)
    road = OpenDriveMap.from_file(ROADS / "alks_road_left_radius_250m.xodr").road("0")
    lanes, plan = _lanes([road]), RoadArrays(*road.plan_view.arrays())
    n = 6
    rows = np.arange(n)[::-1].copy()
    st = np.zeros((len(MK.STATE), n))
    st[MK.S] = rng.uniform(50.0, 250.0, n)
    st[MK.T] = [road.lane_t(-1, s) for s in st[MK.S]]
    st[MK.V] = rng.uniform(5.0, 30.0, n)
    long_par = np.zeros((n, 8))
    long_par[:, MK.L_V0], long_par[:, MK.L_GOAL] = st[MK.V], rng.uniform(0.0, 30.0, n)
    long_par[:, MK.L_SHAPE], long_par[:, MK.L_SPAN] = LINEAR, 2.0
    cx, cy, length = rng.uniform(0, 2, n), rng.uniform(-0.5, 0.5, n), rng.uniform(3, 6, n)
    off = np.zeros(n, bool)

    def tables(has_long: np.ndarray) -> tuple[ActorArrays, CommandArrays]:
        actors = _actors(
            st.copy(), road_code=np.zeros(n, np.intp), lane=np.full(n, -1, np.int64),
            has_long=has_long, long_par=long_par.copy(),
        )  # fmt: skip
        cmd = CommandArrays(
            rows, cx, cy, length, np.full(n, np.nan), np.full((n, 3), -2, np.int64),
            np.zeros((n, 2)), np.zeros(n), np.zeros(n), np.zeros((3, n)),
        )  # fmt: skip
        return actors, cmd

    for has_long, now, commanded in ((off, 1.0, True), (~off, 3.0, False)):
        one, two = tables(has_long), tables(has_long)
        *got, changed = advance_and_command(
            rows, now, 0.05, False, *_plain(one[0], lanes, plan, one[1])
        )
        want = MK.advance_and_place(rows, now, 0.05, False, *_plain(two[0], lanes, plan))
        assert tuple(got) == want
        if commanded:
            want = command_step(*_plain(two[1], two[0], lanes))
            assert changed.tolist() == want.tolist() == rows.tolist()
        else:
            assert got[0] == n and not len(changed)
        for a, b in zip(one, two, strict=True):
            assert all(np.array_equal(x, y, equal_nan=True) for x, y in zip(a, b, strict=True))


def test_command_step_is_command_rows_and_lane_keys(curved_road: object) -> None:
    lanes = _lanes([curved_road])
    rng = np.random.default_rng(5)
    n = 6
    rows = np.arange(n)
    st = np.zeros((len(MK.STATE), n))
    st[MK.S], st[MK.H], st[MK.V] = rng.uniform(0, 1200, n), rng.uniform(-3, 3, n), 10.0
    lane = rng.choice([-1, -2, 1], n)
    actors = _actors(st, road_code=np.zeros(n, np.intp), lane=lane)
    cx, cy, length, sent = rng.uniform(0, 2, n), np.zeros(n), np.full(n, 4.5), np.full(n, 10.0)

    def table() -> CommandArrays:
        return CommandArrays(
            rows, cx, cy, length, sent.copy(), np.full((n, 3), -2, np.int64), np.zeros((n, 2)),
            np.zeros(n), np.zeros(n), np.zeros((3, n)),
        )  # fmt: skip

    one, two = table(), table()
    got = command_step(*_plain(one, actors, lanes))
    command_rows(*_plain(two, actors))
    want = lane_keys(*_plain(two, actors, lanes))
    assert got.tolist() == want.tolist() == list(range(n))
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(one, two, strict=True))


@pytest.mark.parametrize("shape", [LINEAR, SINUSOIDAL])
def test_lane_change_keeps_the_speed_along_the_path(shape: int) -> None:
    """A lane change at v = 10 m/s over T = 2 s on a straight road: every step the actor moves
    v * dt along its path (the lateral share is taken out of the distance along the lane), so
    over the change it travels exactly v * T; with the linear shape the lateral speed is the
    constant W / T, and s advances by T * sqrt(v^2 - (W / T)^2) (W: the lane width). The
    heading slips by asin(v_lat / v), the direction of the motion."""
    road = OpenDriveMap.from_file(ROADS / "alks_road_straight.xodr").road("0")
    lanes = _lanes([road])
    v, big_t, dt, s0 = 10.0, 2.0, 0.05, 100.0
    t0, t1 = road.lane_t(-1, s0), road.lane_t(-2, s0)
    w = abs(t1 - t0)
    st = np.zeros((len(MK.STATE), 1))
    st[MK.S, 0], st[MK.T, 0], st[MK.V, 0] = s0, t0, v
    lat = np.zeros((1, 9))
    lat[0, [MK.T_T0, MK.T_SHAPE, MK.T_SPAN, MK.T_LANE]] = t0, shape, big_t, -2
    rows = np.array([0])
    actors = _actors(st, has_lat=np.ones(1, bool), lat_par=lat)
    done = actors.lat_done
    path = 0.0
    for k in range(1, round(big_t / dt) + 1):
        s_old, t_old = st[MK.S, 0], st[MK.T, 0]
        MK.advance_long(rows, k * dt, dt, tuple(actors))
        MK.advance_lat(rows, k * dt, dt, *_plain(actors, lanes))
        step = math.hypot(st[MK.S, 0] - s_old, st[MK.T, 0] - t_old)
        assert step == pytest.approx(v * dt, abs=1e-12)
        path += step
        if shape == LINEAR:
            assert abs(st[MK.V_LAT, 0]) == pytest.approx(w / big_t, abs=1e-9)
    assert bool(done[0]) and st[MK.T, 0] == pytest.approx(t1, abs=1e-12)
    assert path == pytest.approx(v * big_t, abs=1e-9)
    if shape == LINEAR:
        assert st[MK.S, 0] - s0 == pytest.approx(big_t * math.sqrt(v**2 - (w / big_t) ** 2))
        MK.place_rows(rows, *_plain(RoadArrays(*road.plan_view.arrays()), actors))
        # the reference line heads along x here (h = 0): the heading is the motion's slip
        assert st[MK.H, 0] == pytest.approx(math.asin(st[MK.V_LAT, 0] / v), abs=1e-12)
