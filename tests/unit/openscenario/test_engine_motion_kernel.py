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


def _long_row(v0: float, goal: float, shape: int, span: float, t0: float = 0.0) -> np.ndarray:
    row = np.zeros(8)
    row[[MK.L_V0, MK.L_GOAL, MK.L_SHAPE, MK.L_SPAN, MK.L_T0]] = v0, goal, shape, span, t0
    return row


def _advance(long_par: np.ndarray, now: float, dt: float, v: float) -> tuple[float, float, bool]:
    """(v, s, done) of one row starting at s = 0 after one step."""
    st = np.zeros((len(MK.STATE), 1))
    st[MK.V, 0] = v
    done = np.zeros(1, dtype=bool)
    one = np.ones(1, dtype=bool)
    MK.advance_long(np.array([0]), now, dt, np.zeros(1), np.ones(1), st, one, long_par[None], done)
    return float(st[MK.V, 0]), float(st[MK.S, 0]), bool(done[0])


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
    prof = lane_profile([curved_road]).arrays()
    target = curved_road.lane_t(-2, 400.0)
    t0 = curved_road.lane_t(-1, 400.0)
    row = np.zeros(9)
    row[[MK.T_T0, MK.T_SHAPE, MK.T_SPAN, MK.T_LANE, MK.T_OFFSET]] = t0, SINUSOIDAL, 4.0, -2, 0.25
    st = np.zeros((len(MK.STATE), 1))
    st[MK.S, 0], st[MK.T, 0] = 400.0, t0
    done = np.zeros(1, dtype=bool)
    for now, want_done in ((2.0, False), (4.0, True)):
        args = (np.zeros(1), np.ones(1), st, np.ones(1, dtype=bool), row[None, :], done, *prof)
        missing, n_done = MK.advance_lat(np.array([0]), now, 0.05, *args)
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
    command_rows(rows, st, cx, cy, length, sent.copy(), centres, heading, send, sumo)
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
    MK.place_posed(rows, px, py, pz, h_ref, direction, st)
    lat = direction * v_lat  # the speed is along the path: the lane's share is the rest
    along = np.copysign(np.sqrt(np.maximum(0.0, v * v - lat * lat)), v)
    slip = np.where(np.abs(v) > 1e-6, np.arctan2(lat, along), 0.0)[rows]
    hh = h_ref + np.where(direction[rows] > 0, 0.0, np.pi) + slip + h_rel[rows]
    assert np.array_equal(st[MK.H][rows], np.remainder(hh + np.pi, 2 * np.pi) - np.pi)
    assert np.array_equal(st[MK.X][rows], px)


def test_lane_keys_flag_road_lane_and_section_changes(curved_road: object) -> None:
    prof = lane_profile([curved_road])
    rows = np.array([0, 1])
    free, code, lane = np.zeros(2, dtype=bool), np.zeros(2, dtype=np.intp), np.array([-1, -2])
    key = np.full((2, 3), -2, dtype=np.int64)

    def changed(s: list[float]) -> list[int]:
        args = (prof.sec_first, prof.sec_count, prof.sec_s0, key)
        return lane_keys(rows, free, code, lane, np.array(s), *args).tolist()

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
    prof, plan = lane_profile([road]).arrays(), road.plan_view
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
        one = [st.copy(), long_par.copy(), lat_par.copy(), np.zeros(n, bool), np.zeros(n, bool)]
        two = [x.copy() for x in one]
        got = MK.advance_and_place(
            rows, now, 0.05, kappa, direction, one[0], has_long, one[1], one[3], has_lat,
            one[2], one[4], True, *prof, *plan.arrays(),
        )  # fmt: skip
        n_long = MK.advance_long(
            rows, now, 0.05, kappa, direction, two[0], has_long, two[1], two[3]
        )
        missing, n_lat = MK.advance_lat(
            rows, now, 0.05, kappa, direction, two[0], has_lat, two[2], two[4], *prof
        )
        if want_placed:
            MK.place_rows(rows, *plan.arrays(), direction, two[0])
        assert got == (n_long, missing, n_lat, want_placed)
        assert all(np.array_equal(a, b) for a, b in zip(one, two, strict=True))


def test_advance_and_command_commands_only_when_nothing_ended() -> None:
    """The motion step and the commands in one call leave the same arrays, bit for bit, as
    advance_and_place then command_step; when a transition ends (the storyboard ends its
    action first) the commands are left to the caller, their arrays untouched."""
    rng = np.random.default_rng(5)
    road = OpenDriveMap.from_file(ROADS / "alks_road_left_radius_250m.xodr").road("0")
    profile = lane_profile([road])
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
    off, none = np.zeros(n, bool), np.zeros(n, bool)

    def motion(x: list, has_long: np.ndarray, now: float) -> tuple:
        return (
            rows, now, 0.05, np.zeros(n), np.ones(n), x[0], has_long, x[1], x[2], none,
            np.zeros((n, 9)), none, False, *profile.arrays(), *road.plan_view.arrays(),
        )  # fmt: skip

    def command(x: list) -> tuple:
        return (
            rows, x[0], cx, cy, length, *x[3:8], none, np.zeros(n, np.intp),
            np.full(n, -1, np.int64), profile.sec_first, profile.sec_count,
            profile.sec_s0, x[8],
        )  # fmt: skip

    for has_long, now, commanded in ((off, 1.0, True), (~off, 3.0, False)):
        one = [st.copy(), long_par.copy(), np.zeros(n, bool), np.full(n, np.nan),
               np.zeros((n, 2)), np.zeros(n), np.zeros(n), np.zeros((3, n)),
               np.full((n, 3), -2, np.int64)]  # fmt: skip
        two = [x.copy() for x in one]
        *got, changed = advance_and_command(*motion(one, has_long, now), *command(one))
        assert tuple(got) == MK.advance_and_place(*motion(two, has_long, now))
        if commanded:
            assert changed.tolist() == command_step(*command(two)).tolist() == rows.tolist()
        else:
            assert got[0] == n and not len(changed)
        assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(one, two, strict=True))


def test_command_step_is_command_rows_and_lane_keys(curved_road: object) -> None:
    prof = lane_profile([curved_road])
    rng = np.random.default_rng(5)
    n = 6
    rows = np.arange(n)
    st = np.zeros((len(MK.STATE), n))
    st[MK.S], st[MK.H], st[MK.V] = rng.uniform(0, 1200, n), rng.uniform(-3, 3, n), 10.0
    free, code, lane = np.zeros(n, bool), np.zeros(n, np.intp), rng.choice([-1, -2, 1], n)
    cx, cy, length, sent = rng.uniform(0, 2, n), np.zeros(n), np.full(n, 4.5), np.full(n, 10.0)
    sec = (prof.sec_first, prof.sec_count, prof.sec_s0)

    def outs() -> list[np.ndarray]:
        return [np.zeros((n, 2)), np.zeros(n), np.zeros(n), np.zeros((3, n))]

    one, two = outs(), outs()
    key1, key2 = np.full((n, 3), -2, np.int64), np.full((n, 3), -2, np.int64)
    got = command_step(rows, st, cx, cy, length, sent.copy(), *one, free, code, lane, *sec, key1)
    command_rows(rows, st, cx, cy, length, sent.copy(), *two)
    want = lane_keys(rows, free, code, lane, st[MK.S], *sec, key2)
    assert got.tolist() == want.tolist() == list(range(n)) and np.array_equal(key1, key2)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(one, two, strict=True))


@pytest.mark.parametrize("shape", [LINEAR, SINUSOIDAL])
def test_lane_change_keeps_the_speed_along_the_path(shape: int) -> None:
    """A lane change at v = 10 m/s over T = 2 s on a straight road: every step the actor moves
    v * dt along its path (the lateral share is taken out of the distance along the lane), so
    over the change it travels exactly v * T; with the linear shape the lateral speed is the
    constant W / T, and s advances by T * sqrt(v^2 - (W / T)^2) (W: the lane width). The
    heading slips by asin(v_lat / v), the direction of the motion."""
    road = OpenDriveMap.from_file(ROADS / "alks_road_straight.xodr").road("0")
    prof = lane_profile([road]).arrays()
    v, big_t, dt, s0 = 10.0, 2.0, 0.05, 100.0
    t0, t1 = road.lane_t(-1, s0), road.lane_t(-2, s0)
    w = abs(t1 - t0)
    st = np.zeros((len(MK.STATE), 1))
    st[MK.S, 0], st[MK.T, 0], st[MK.V, 0] = s0, t0, v
    lat = np.zeros((1, 9))
    lat[0, [MK.T_T0, MK.T_SHAPE, MK.T_SPAN, MK.T_LANE]] = t0, shape, big_t, -2
    rows, one, zero = np.array([0]), np.ones(1), np.zeros(1)
    no, yes, done = np.zeros(1, bool), np.ones(1, bool), np.zeros(1, bool)
    path = 0.0
    for k in range(1, round(big_t / dt) + 1):
        s_old, t_old = st[MK.S, 0], st[MK.T, 0]
        MK.advance_long(rows, k * dt, dt, zero, one, st, no, np.zeros((1, 8)), done)
        MK.advance_lat(rows, k * dt, dt, zero, one, st, yes, lat, done, *prof)
        step = math.hypot(st[MK.S, 0] - s_old, st[MK.T, 0] - t_old)
        assert step == pytest.approx(v * dt, abs=1e-12)
        path += step
        if shape == LINEAR:
            assert abs(st[MK.V_LAT, 0]) == pytest.approx(w / big_t, abs=1e-9)
    assert bool(done[0]) and st[MK.T, 0] == pytest.approx(t1, abs=1e-12)
    assert path == pytest.approx(v * big_t, abs=1e-9)
    if shape == LINEAR:
        assert st[MK.S, 0] - s0 == pytest.approx(big_t * math.sqrt(v**2 - (w / big_t) ** 2))
        MK.place_rows(rows, *road.plan_view.arrays(), one, st)
        # the reference line heads along x here (h = 0): the heading is the motion's slip
        assert st[MK.H, 0] == pytest.approx(math.asin(st[MK.V_LAT, 0] / v), abs=1e-12)
