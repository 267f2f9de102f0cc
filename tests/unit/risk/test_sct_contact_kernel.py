"""The compiled SCT kernels (first contact, path sampling, dart-out kerbs, conflict zones, crossing
stops, study scan, carriageway test, ramps) equal numpy / shapely: bit for bit, or within a few ULP where numpy takes a transcendental
function (tests/support/ulp.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from sct_reference import near_pairs, ramp_profiles
from ulp import assert_within_ulps

from hiyari.bridge.loop.drivers.sct_controller import travel
from hiyari.bridge.studies.sct.scan import zone_scan
from hiyari.kinematics import footprint_corners, overlap_depth
from hiyari.risk.metrics.contact import (
    ContactGeometry,
    Path,
    SCTConfig,
    contact_gap,
    crossing_conflict,
    first_contact_time,
    pedestrian_velocity,
)
from hiyari.risk.metrics.pedestrian_geometry import KerbSegments
from hiyari.risk.sct.area_kernel import AreaTest, locate_xy
from hiyari.risk.sct.contact_kernel import (
    first_contacts,
    pair_time_bounds,
    within_reach,
)
from hiyari.risk.sct.model import PathTable, Segments
from hiyari.risk.sct.pair_kernel import crossing_zones
from hiyari.risk.sct.plan_kernel import _ramps, stops_on_crossing

#: compiled kernels against numpy formulas: CI runs these again with numpy's dispatch limited
pytestmark = pytest.mark.kernels


def _reference(vxy, vh, length, width, contact, tracks, exposed, a, t, times):
    gap = contact_gap(vxy[a], vh[a], length[a, None], width[a, None], tracks[t], contact)  # (n, K)
    gap = np.where(exposed[t], gap, np.inf)
    return first_contact_time(gap, times), gap[:, 0] > 0


def test_kernel_equals_numpy_bit_for_bit():
    rng = np.random.default_rng(7)
    times = np.arange(51) * 0.2
    n_a, n_t = 40, 60
    # vehicles driving along x through the pedestrians' area, pedestrians crossing it
    start = rng.uniform(-30, 0, (n_a, 1, 2))
    speed = rng.uniform(0, 15, (n_a, 1, 1))
    heading = rng.uniform(-np.pi, np.pi, (n_a, len(times)))
    vxy = start + speed * times[None, :, None] * np.stack([np.cos(heading), np.sin(heading)], -1)
    tracks = (
        rng.uniform(-10, 10, (n_t, 1, 2)) + rng.normal(0, 1.5, (n_t, 1, 2)) * times[None, :, None]
    )
    tracks[:5] = vxy[:5]  # touching from the first sample
    exposed = rng.random((n_t, len(times))) < 0.8
    exposed[5:10] = False  # protected throughout
    length, width = rng.uniform(3, 12, n_a), rng.uniform(1.5, 2.6, n_a)
    a = np.repeat(np.arange(n_a), n_t)
    t = np.tile(np.arange(n_t), n_a)
    contact = ContactGeometry(0.2, 0.3)
    first, apart = first_contacts(
        vxy, heading, length, width, 0.2, 0.3, tracks, exposed, a, t, times
    )
    ref_first, ref_apart = _reference(
        vxy, heading, length, width, contact, tracks, exposed, a, t, times
    )
    assert np.isfinite(first).sum() > 100 and np.isinf(first).sum() > 100  # both kinds occur
    assert (first == 0).any() and not apart.all()  # contacts from the first sample too
    assert np.array_equal(first, ref_first)
    assert np.array_equal(apart, ref_apart)
    assert first.tobytes() == ref_first.tobytes()


def test_kernel_interpolates_between_samples():
    # a point pedestrian standing 5 m ahead of a 4 m x 2 m car driving at 10 m/s along +x:
    # the front (2 m ahead of the centre) reaches x = 5 - 0.3 at t = 0.27 s
    times = np.arange(11) * 0.1
    vxy = np.stack([10.0 * times, np.zeros_like(times)], -1)[None]
    tracks = np.tile([5.0, 0.0], (1, len(times), 1))
    first, apart = first_contacts(
        vxy,
        np.zeros((1, len(times))),
        np.array([4.0]),
        np.array([2.0]),
        0.0,
        0.3,
        tracks,
        np.ones((1, len(times)), bool),
        np.array([0]),
        np.array([0]),
        times,
    )
    assert apart[0]
    assert abs(first[0] - 0.27) < 1e-12


def _path_at_reference(table, vehicles, s):
    """PathTable.at in numpy (its former implementation)."""
    shape = (len(vehicles), *([1] * (s.ndim - 1)))
    cum = table.cum[vehicles].reshape(*shape, -1)
    k = np.maximum((s[..., None] >= cum).sum(axis=-1) - 1, 0)
    k = np.minimum(k, (table.count[vehicles] - 1).reshape(shape))
    k += table.first[vehicles].reshape(shape)
    seg = table.seg
    return seg.start[k] + seg.unit[k] * (s - seg.cum_start[k])[..., None], seg.heading[k]


def test_path_sampling_equals_numpy_bit_for_bit():
    rng = np.random.default_rng(3)
    paths = []
    for n in (2, 5, 40):  # a straight segment, a few, a curve of many
        angle = np.cumsum(rng.normal(0, 0.2, n))
        steps = rng.uniform(0.5, 4.0, (n, 1)) * np.stack([np.cos(angle), np.sin(angle)], -1)
        paths.append(Path.of(np.cumsum(steps, axis=0)))
    table = PathTable.of([Segments.of(p) for p in paths])
    vehicles = np.array([2, 0, 1, 2])
    # before the start, on the path, at its vertices, beyond the end
    s = rng.uniform(-20, 200, (4, 3, 51))
    s[0, 0, :5] = paths[2].cum[:5]
    xy, hd = table.at(vehicles, s)
    ref_xy, ref_hd = _path_at_reference(table, vehicles, s)
    assert xy.shape == (4, 3, 51, 2) and hd.shape == (4, 3, 51)
    assert xy.tobytes() == ref_xy.tobytes() and hd.tobytes() == ref_hd.tobytes()
    # and each equals sampling the vehicle's own Path
    for i, v in enumerate(vehicles):
        p_xy, p_hd = paths[v].at(s[i])
        assert np.allclose(xy[i], p_xy, atol=1e-9) and np.allclose(hd[i], p_hd, atol=1e-12)


def _velocity_reference(xy, heading, speed, on_kerb, kerbs, config, open_crossings):
    """pedestrian_velocity in numpy (its former implementation)."""
    u = np.stack([np.cos(heading), np.sin(heading)], -1)
    vel = speed[:, None] * u
    dart = np.zeros(len(xy), bool)
    cr = kerbs.crossing
    usable = (cr < 0) | np.asarray(open_crossings, bool)[np.maximum(cr, 0)]
    rows = np.flatnonzero(on_kerb)
    ab = kerbs.b - kerbs.a
    L2 = np.maximum(np.einsum("kj,kj->k", ab, ab), 1e-12)
    ap = xy[rows][:, None, :] - kerbs.a[None]
    f = np.clip(np.einsum("pkj,kj->pk", ap, ab) / L2, 0.0, 1.0)
    to_seg = f[..., None] * ab[None] - ap
    dist = np.linalg.norm(to_seg, axis=2)
    cos_max = math.cos(math.radians(config.dart_out_max_angle_deg))
    facing = u[rows] @ kerbs.inward.T >= cos_max
    toward = np.einsum("pj,pkj->pk", u[rows], to_seg) >= cos_max * np.maximum(dist, 1e-9)
    facing |= toward & (kerbs.crossing >= 0)[None] & (dist > 0.1)
    ok = facing & usable[None] & (dist <= config.dart_out_distance)
    dist = np.where(ok, dist, np.inf)
    best = np.argmin(dist, axis=1)
    hit = np.isfinite(dist[np.arange(len(rows)), best])
    r = rows[hit]
    vel[r] = np.maximum(speed[r], config.dart_out_speed)[:, None] * kerbs.inward[best[hit]]
    dart[r] = True
    return vel, dart


def test_pedestrian_velocity_equals_numpy_bit_for_bit():
    rng = np.random.default_rng(11)
    k = 40
    a = rng.uniform(-30, 30, (k, 2))
    angle = rng.uniform(-np.pi, np.pi, k)
    b = a + rng.uniform(0.5, 8, (k, 1)) * np.stack([np.cos(angle), np.sin(angle)], -1)
    inward = np.stack([-np.sin(angle), np.cos(angle)], -1)
    crossing = np.where(rng.random(k) < 0.3, rng.integers(0, 4, k), -1)
    kerbs = KerbSegments(a, b, inward, crossing)
    n = 3000
    # pedestrians near the kerbs: many within the dart-out distance, some exactly on one
    near = rng.integers(0, k, n)
    xy = a[near] + rng.uniform(0, 1, (n, 1)) * (b - a)[near] + rng.normal(0, 1.2, (n, 2))
    xy[:50] = a[near[:50]]
    heading = rng.uniform(-np.pi, np.pi, n)
    speed = rng.uniform(0, 2, n)
    speed[:200] = 0.0
    on_kerb = rng.random(n) < 0.8
    config = SCTConfig()
    for open_crossings in (np.ones(4, bool), np.array([True, False, True, False])):
        vel, dart = pedestrian_velocity(xy, heading, speed, on_kerb, kerbs, config, open_crossings)
        ref_vel, ref_dart = _velocity_reference(
            xy, heading, speed, on_kerb, kerbs, config, open_crossings
        )
        assert 100 < dart.sum() < n  # dart-outs and plain walkers both occur
        assert np.array_equal(dart, ref_dart)
        assert vel.tobytes() == ref_vel.tobytes()


def test_near_pairs_equals_numpy_and_never_misses_a_contact():
    rng = np.random.default_rng(5)
    times = np.arange(51) * 0.2
    n_a, n_t = 30, 50
    heading = rng.uniform(-np.pi, np.pi, (n_a, len(times)))
    vxy = rng.uniform(-20, 20, (n_a, 1, 2)) + rng.uniform(0, 12, (n_a, 1, 1)) * times[
        None, :, None
    ] * np.stack([np.cos(heading[:, :1]), np.sin(heading[:, :1])], -1)
    tracks = (
        rng.uniform(-20, 20, (n_t, 1, 2)) + rng.normal(0, 1.5, (n_t, 1, 2)) * times[None, :, None]
    )
    length, width = rng.uniform(3, 12, n_a), rng.uniform(1.5, 2.6, n_a)
    a = np.repeat(np.arange(n_a), n_t)
    t = np.tile(np.arange(n_t), n_a)
    upto = rng.integers(1, len(times) + 1, len(a))
    near = near_pairs(vxy, length, width, 0.2, 0.3, tracks, a, t, upto)
    # the former numpy form, per pair up to its own sample
    reach = np.hypot(0.5 * length + 0.2, 0.5 * width + 0.2) + 0.3 + 1e-6
    ref = np.array(
        [
            ((tracks[j, :u] - vxy[i, :u]) ** 2).sum(-1).min() <= reach[i] * reach[i]
            for i, j, u in zip(a, t, upto, strict=True)
        ]
    )
    assert 50 < near.sum() < len(near) - 50
    assert np.array_equal(near, ref)
    # a pair that is not near has no contact at any of those samples
    first, _ = first_contacts(
        vxy,
        heading,
        length,
        width,
        0.2,
        0.3,
        tracks,
        np.ones((n_t, len(times)), bool),
        a,
        t,
        times,
    )
    touched = first < times[upto - 1]  # a contact at a sample before upto
    assert touched.sum() > 10 and near[touched].all()


def _travel_reference(accel, v0, v_max, dt, stop_speed=0.0):
    """controller.travel in numpy (its former implementation)."""
    zero = np.zeros((*accel.shape[:-1], 1))
    dv = 0.5 * (accel[..., 1:] + accel[..., :-1]) * dt
    v = np.clip(v0 + np.concatenate([zero, np.cumsum(dv, -1)], -1), 0, v_max)
    if stop_speed > 0:
        slow = (v < stop_speed) & (accel[..., -1:] <= 0)
        v = np.where(np.logical_or.accumulate(slow, axis=-1), 0.0, v)
    ds = 0.5 * (v[..., 1:] + v[..., :-1]) * dt
    return v, np.concatenate([zero, np.cumsum(ds, -1)], -1)


def test_travel_equals_numpy_bit_for_bit():
    rng = np.random.default_rng(2)
    times = np.arange(51) * 0.2
    targets = np.linspace(-4, 1.5, 12)
    a0 = rng.uniform(-3, 2, 20)
    accel = ramp_profiles(a0, targets, times, 3.0)  # (20, 12, 51)
    v0 = rng.uniform(0, 15, (20, 1, 1))
    v0[:3] = 0.0
    v_max = np.maximum(rng.uniform(8, 16, (20, 1, 1)), v0)
    for stop in (0.0, 1.0):
        v, s = travel(accel, v0, v_max, 0.2, stop)
        ref_v, ref_s = _travel_reference(accel, v0, v_max, 0.2, stop)
        assert v.tobytes() == ref_v.tobytes() and s.tobytes() == ref_s.tobytes()
    assert (v == 0).any() and (v == v_max).any()  # both clips were exercised
    v, s = travel(np.full((1, 11), -2.0), 10.0, 14.0, 0.1)  # scalars broadcast too
    ref_v, ref_s = _travel_reference(np.full((1, 11), -2.0), 10.0, 14.0, 0.1)
    assert v.tobytes() == ref_v.tobytes() and s.tobytes() == ref_s.tobytes()


def _project_reference(table, xy):
    """PathTable.project in numpy (its former implementation)."""
    s, own = table.seg, table.owner
    p = xy[own]
    f = np.clip(np.einsum("ij,ij->i", p - s.start, s.vector) / s.length2, 0.0, 1.0)
    d = np.linalg.norm(s.start + f[:, None] * s.vector - p, axis=1)
    low = np.minimum.reduceat(d, table.first)
    hit = np.flatnonzero(d == low[own])
    k = hit[np.searchsorted(own[hit], np.arange(len(table.first)))]
    return s.cum_start[k] + f[k] * np.sqrt(s.length2[k])


def test_projection_equals_numpy_bit_for_bit():
    rng = np.random.default_rng(4)
    paths = []
    for n in rng.integers(2, 60, 30):
        angle = np.cumsum(rng.normal(0, 0.3, n))
        steps = rng.uniform(0.5, 4.0, (n, 1)) * np.stack([np.cos(angle), np.sin(angle)], -1)
        paths.append(Path.of(np.cumsum(steps, axis=0)))
    table = PathTable.of([Segments.of(p) for p in paths])
    xy = np.array([p.points[len(p.points) // 2] for p in paths]) + rng.normal(0, 3, (30, 2))
    xy[0] = paths[0].points[0]  # on a vertex: two segments at the same distance
    s = table.project(xy)
    assert s.tobytes() == _project_reference(table, xy).tobytes()
    assert np.allclose(s, [p.project(q) for p, q in zip(paths, xy, strict=True)])


def test_pair_time_bounds_equal_numpy_bit_for_bit():
    rng = np.random.default_rng(9)
    vxy, pxy = rng.uniform(-80, 80, (12, 2)), rng.uniform(-20, 20, (9, 2))
    length, width = rng.uniform(3, 12, 12), rng.uniform(1.5, 2.6, 12)
    speed = rng.uniform(0, 15, 12)
    reach = 0.5 * np.hypot(length, width) + 0.2
    tau_now, tau_acc = pair_time_bounds(vxy, pxy, reach, 0.3, speed, 2.5, 3.0)
    d = np.sqrt(((vxy[:, None] - pxy[None]) ** 2).sum(-1))
    gap = np.maximum(d - reach[:, None] - 0.3, 0.0)
    closing = speed[:, None] + 2.5
    assert tau_now.tobytes() == (gap / closing).tobytes()
    ref_acc = 2.0 * gap / (closing + np.sqrt(closing**2 + 2.0 * 3.0 * gap))
    assert tau_acc.tobytes() == ref_acc.tobytes()
    assert (tau_acc <= tau_now).all()  # accelerating can only bring contact earlier


def test_within_reach_equals_numpy():
    rng = np.random.default_rng(10)
    vxy, pxy = rng.uniform(-80, 80, (40, 2)), rng.uniform(-20, 20, (7, 2))
    reach = rng.uniform(2, 7, 40)
    speed, ped_speed = rng.uniform(0, 15, 40), rng.uniform(0, 3, 7)
    out = within_reach(vxy, pxy, reach, 0.3, speed, ped_speed, 4.0, 0.5 * 3.0 * 4.0 * 4.0)
    gap = np.linalg.norm(vxy[:, None] - pxy[None], axis=2) - reach[:, None] - 0.3
    ref = (gap <= (speed[:, None] + ped_speed[None]) * 4.0 + 0.5 * 3.0 * 4.0 * 4.0).any(axis=1)
    assert 5 < ref.sum() < 35 and np.array_equal(out, ref)


def test_crossing_zones_equal_crossing_conflict():
    """The compiled conflict-zone occupancy equals contact.crossing_conflict per vehicle:
    paths crossing the crossings' lines at all angles (parallel ones too), pedestrians on,
    beside and beyond the crossings, vehicles before, in and past the zones."""
    rng = np.random.default_rng(11)
    paths = []
    for n in (2, 6, 30):
        angle = rng.uniform(-np.pi, np.pi) + np.cumsum(rng.normal(0, 0.15, n))
        steps = rng.uniform(1.0, 5.0, (n, 1)) * np.stack([np.cos(angle), np.sin(angle)], -1)
        paths.append(Path.of(np.cumsum(steps, axis=0) - 20.0))
    paths.append(Path.of(np.array([[-30.0, 0.0], [30.0, 0.0]])))  # parallel to some crossings
    table = PathTable.of([Segments.of(p) for p in paths])
    n = 400
    vslot = rng.integers(0, len(paths), n)
    s_vehicle = rng.uniform(-5, 80, n)
    length, width = rng.uniform(3.5, 5.5, n), rng.uniform(1.6, 2.1, n)
    theta = rng.uniform(-np.pi, np.pi, n)
    theta[:40] = 0.0  # along the straight path: det 0
    direction = np.stack([np.cos(theta), np.sin(theta)], -1)
    # crossings through a point of the vehicle's path (most), pedestrians along them
    on_path = np.array([paths[v].at(rng.uniform(0, paths[v].cum[-1]))[0] for v in vslot])
    centre = on_path + rng.normal(0, 1.5, (n, 2))
    ped = centre + direction * rng.uniform(-8, 8, (n, 1)) + rng.normal(0, 0.3, (n, 2))
    ped[-40:] = rng.uniform(-25, 25, (40, 2))  # anywhere
    half = rng.uniform(2, 8, n)
    seg = table.seg
    got = crossing_zones(
        vslot,
        s_vehicle,
        length,
        width,
        table.count,
        table.first,
        seg.start,
        seg.vector,
        seg.cum_start,
        ped,
        direction,
        centre,
        half,
        0.3,
    )
    for i in range(n):
        want = crossing_conflict(
            paths[vslot[i]],
            s_vehicle[i],
            length[i],
            width[i],
            ped[i : i + 1],
            direction[i : i + 1],
            centre[i : i + 1],
            half[i : i + 1],
            0.3,
        )
        assert [bool(g[i]) for g in got] == [bool(w[0]) for w in want], i
    assert 50 < got[0].sum() < n and got[1].any() and got[2].any() and (~got[1] & got[0]).any()


def test_segment_headings_cos_sin_are_numpys():
    """The per-segment cos / sin the kernels read are numpy's cos / sin of the headings that
    path sampling returns (so contact_gap's rotation is unchanged)."""
    rng = np.random.default_rng(5)
    angle = np.cumsum(rng.normal(0, 0.5, 200))
    steps = rng.uniform(0.5, 4.0, (200, 1)) * np.stack([np.cos(angle), np.sin(angle)], -1)
    table = PathTable.of([Segments.of(Path.of(np.cumsum(steps, axis=0)))])
    s = rng.uniform(-10, 600, (1, 997))
    _, hd = table.at(np.array([0]), s)
    k = np.array([int(np.argmax(table.seg.heading == h)) for h in hd.ravel()])
    assert np.cos(hd).ravel().tobytes() == table.seg.cos[k].tobytes()
    assert np.sin(hd).ravel().tobytes() == table.seg.sin[k].tobytes()


def test_stops_on_crossing_equals_footprint_overlap():
    """The compiled stop-on-crossing test equals kinematics.footprint_corners and
    overlap_depth > 0 on every stopped candidate (rectangles touching, overlapping and apart
    from rotated crossings), and leaves moving candidates out."""
    rng = np.random.default_rng(17)
    n_a = 6
    centre = rng.uniform(-20, 20, (n_a, 2))
    direction = rng.uniform(-np.pi, np.pi, n_a)
    half_length, half_width = rng.uniform(3, 8, n_a), rng.uniform(1.5, 3, n_a)
    corners = footprint_corners(centre, direction, 2 * half_length, 2 * half_width)
    w, c = 60, 12
    length, width = rng.uniform(3.5, 5.5, w), rng.uniform(1.6, 2.1, w)
    near = rng.integers(0, n_a, (w, c))
    xy = centre[near] + rng.normal(0, 5, (w, c, 2))
    heading = rng.uniform(-np.pi, np.pi, (w, c))
    v_end = np.where(rng.random((w, c)) < 0.7, 0.0, 1.0)
    got = stops_on_crossing(
        xy,
        np.cos(heading),
        np.sin(heading),
        v_end,
        length,
        width,
        0.5 * np.hypot(length, width),
        np.hypot(half_length, half_width),
        centre,
        corners,
    )
    rect = footprint_corners(xy, heading, length[:, None], width[:, None])  # (w, c, 4, 2)
    depth = overlap_depth(
        np.repeat(rect.reshape(-1, 4, 2), n_a, 0), np.tile(corners, (w * c, 1, 1))
    ).reshape(w, c, n_a)
    want = (v_end <= 0.0) & (depth > 0).any(axis=2)
    assert np.array_equal(got, want)
    assert 20 < got.sum() < (v_end <= 0.0).sum()  # overlapping and clear stops both occur


def test_zone_scan_equals_the_numpy_scan():
    """The study's compiled per-step scan gives the numpy scan's zones, logged pairs, planning
    flag and least bound."""
    rng = np.random.default_rng(23)
    centres = np.array([[150.0, 150.0], [400.0, 150.0]])
    for _ in range(50):
        n = int(rng.integers(0, 40))
        xy = centres[rng.integers(0, 2, n)] + rng.normal(0, 40, (n, 2))
        is_ped = rng.random(n) < 0.6
        length, width = rng.uniform(0.2, 5, n), rng.uniform(0.2, 2, n)
        speed = rng.uniform(0, 15, n)
        got = zone_scan(
            xy,
            is_ped,
            centres,
            80.0**2,
            20.0**2,
            length,
            width,
            0.2,
            0.3,
            speed,
            2.5,
            3.0,
            3.0,
            4.0,
        )
        d2 = ((xy[:, None, :] - centres[None]) ** 2).sum(-1).min(axis=1)
        vin = np.flatnonzero(~is_ped & (d2 <= 80.0**2))
        pin = np.flatnonzero(is_ped & (d2 <= 20.0**2))
        assert got[0].tobytes() == d2.tobytes()
        assert np.array_equal(got[1], vin) and np.array_equal(got[2], pin)
        if len(vin) == 0 or len(pin) == 0:
            assert len(got[3]) == len(got[4]) == 0 and not got[5] and got[6] == np.inf
            continue
        reach = 0.5 * np.hypot(length[vin], width[vin]) + 0.2
        tau_now, tau_acc = pair_time_bounds(
            np.ascontiguousarray(xy[vin]),
            np.ascontiguousarray(xy[pin]),
            reach,
            0.3,
            speed[vin],
            2.5,
            3.0,
        )
        vi, pj = np.nonzero(tau_now <= 3.0)
        assert np.array_equal(got[3], vin[vi]) and np.array_equal(got[4], pin[pj])
        assert got[5] == bool((tau_acc <= 4.0).any()) and got[6] == float(tau_acc.min())


def test_area_test_equals_shapely_contains_xy():
    """AreaTest answers as shapely.contains_xy everywhere: inside, outside, on edges and
    vertices (boundary: not contained), for a polygon with a hole, a multipolygon, a rotated
    star and an axis-aligned cross like the study's carriageway; GEOS is asked only about
    points on (or within rounding of) the boundary."""
    rng = np.random.default_rng(29)
    star_angle = np.linspace(0, 2 * np.pi, 15, endpoint=False)
    star_r = np.where(np.arange(15) % 2 == 0, 30.0, 12.0)
    star = shapely.Polygon(np.stack([star_r * np.cos(star_angle), star_r * np.sin(star_angle)], -1))
    cross = shapely.union(shapely.box(-40, -3.5, 40, 3.5), shapely.box(-3.5, -40, 3.5, 40))
    holed = shapely.Polygon(
        [(-30, -30), (30, -30), (30, 30), (-30, 30)], [[(-10, -10), (10, -10), (0, 15)]]
    )
    multi = shapely.MultiPolygon([shapely.box(-30, -30, -5, -5), shapely.box(5, 5, 30, 30)])
    for area in (star, cross, holed, multi):
        shapely.prepare(area)
        test = AreaTest(area)
        pts = rng.uniform(-45, 45, (4000, 2))
        ring = shapely.get_coordinates(shapely.get_rings(shapely.get_parts(area)))
        a, b = ring[:-1], ring[1:]
        f = rng.uniform(0, 1, (len(a), 1))
        on_edge = a + f * (b - a)  # on (or within rounding of) an edge
        level = np.stack([rng.uniform(-45, 45, len(ring)), ring[:, 1]], -1)  # vertex rows
        pts = np.concatenate([pts, ring, on_edge, on_edge + 1e-13, np.round(pts[:500]), level])
        got = test.contains(pts)
        want = shapely.contains_xy(area, pts[:, 0], pts[:, 1])
        assert np.array_equal(got, want)
        assert 500 < got.sum() < len(pts) - 500
        asked = locate_xy(pts, *test._rings) < 0
        assert asked[:4000].sum() <= 2 and asked[4000 : 4000 + len(ring)].all()
    # shapes of the inputs are kept
    grid = rng.uniform(-45, 45, (3, 4, 5, 2))
    got = AreaTest(cross).contains(grid)
    assert got.shape == (3, 4, 5)
    assert np.array_equal(got, shapely.contains_xy(cross, grid[..., 0], grid[..., 1]))


def test_compiled_ramps_equal_ramp_profiles():
    """The planner's compiled ramps are the numpy oracle's within a few ULP (numpy's pow may
    take a SIMD path that libm's does not)."""
    rng = np.random.default_rng(31)
    a0 = np.concatenate([rng.uniform(-5, 3, 200), [0.0, -3.92, 1.47]])
    targets = np.array([-0.4, -0.25, -0.1, 0.0, 0.05, 0.15]) * 9.80665
    times = np.arange(51) * 0.2
    got = _ramps(a0, targets, times, 3.0)
    assert_within_ulps(got, ramp_profiles(a0, targets, times, 3.0), scale=9.80665)
