"""TTC, SCT, dart-out and PET against hand-computed geometries."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiyari.net.sumo.build import IntersectionParams, build_intersection
from hiyari.risk.metrics.contact import (
    ContactGeometry,
    Path,
    PostEncroachmentTracker,
    SCTConfig,
    contact_gap,
    crossing_conflict,
    first_contact_time,
    pedestrian_velocity,
    safety_cushion_time,
    time_to_contact,
)
from hiyari.risk.metrics.pedestrian_geometry import NetGeometry

R = 0.3  # pedestrian disc radius, m
CAR = dict(veh_length=np.array([4.0]), veh_width=np.array([2.0]))


def ttc(vxy, vh, vvel, pxy, pvel, margin=0.0, horizon=math.inf):
    return float(
        time_to_contact(
            np.array([vxy], float),
            np.array([vh], float),
            np.array([vvel], float),
            CAR["veh_length"],
            CAR["veh_width"],
            np.array([pxy], float),
            np.array([pvel], float),
            ContactGeometry(margin, R),
            horizon,
        )[0]
    )


def test_head_on_ttc_is_gap_over_closing_speed():
    # front face at x = 2, disc touches at x = 2.3; 20 - 2.3 = 17.7 m closed at 10 + 1 m/s
    assert ttc((0, 0), 0.0, (10, 0), (20, 0), (-1, 0)) == pytest.approx(17.7 / 11.0)


def test_right_angle_crossing_hits_the_front_face():
    # pedestrian crosses 15 m ahead from 2 m right of the centre line at 1.5 m/s; the front
    # face (x = 2 + 0.3 relative) is reached after 12.7 / 10 s, when it is 0.095 m right of
    # the centre line, inside the face
    assert ttc((0, 0), 0.0, (10, 0), (15, -2), (0, 1.5)) == pytest.approx(1.27)


def test_right_angle_crossing_that_passes_in_front_never_touches():
    # 5 m to the right it is still 3.1 m off when the car passes: no contact
    assert math.isinf(ttc((0, 0), 0.0, (10, 0), (15, -5), (0, 1.5)))


def test_corner_contact_on_the_rounded_corner():
    # standing car; pedestrian walks at 1 m/s straight at the front-left corner (2, 1) from
    # 5 m away along (-0.6, -0.8): it meets the 0.3 m disc around the corner after 4.7 m
    assert ttc((0, 0), 0.0, (0, 0), (5, 5), (-0.6, -0.8)) == pytest.approx(4.7)


def test_parallel_paths_never_touch():
    assert math.isinf(ttc((0, 0), 0.0, (10, 0), (-20, 3), (1.4, 0)))


def test_rotated_vehicle_frame():
    # the head-on case turned by 90 degrees: car going north
    assert ttc((5, 5), math.pi / 2, (0, 10), (5, 25), (0, -1)) == pytest.approx(17.7 / 11.0)


def test_touching_now_is_zero_and_horizon_cuts():
    assert ttc((0, 0), 0.0, (0, 0), (2.2, 0), (0, 0)) == 0.0
    assert math.isinf(ttc((0, 0), 0.0, (10, 0), (20, 0), (-1, 0), horizon=1.0))


def test_contact_gap_and_margin():
    g = contact_gap(np.zeros(2), 0.0, 4.0, 2.0, np.array([5.0, 4.0]), ContactGeometry(0.2, R))
    # corner (2.2, 1.2) to (5, 4): hypot(2.8, 2.8) - 0.3
    assert float(g) == pytest.approx(math.hypot(2.8, 2.8) - 0.3)


def test_first_contact_time_interpolates_between_samples():
    t = np.arange(0, 5.01, 0.3)
    assert float(first_contact_time(2.0 - t, t)) == pytest.approx(2.0)
    assert math.isinf(float(first_contact_time(1.0 + t, t)))


def test_sct_on_a_straight_path_equals_ttc_with_the_margin():
    cfg = SCTConfig(time_step=0.1, speed_factors=(1.0,))
    path = Path.of(np.array([[-100.0, 0.0], [100.0, 0.0]]))
    xy, hd = path.at(path.project(np.zeros(2)) + 10.0 * cfg.times)
    sct = safety_cushion_time(
        xy[None],
        hd[None],
        np.array([4.0]),
        np.array([2.0]),
        np.array([[15.0, -2.0]]),
        np.array([[0.0, 1.5]]),
        cfg,
    )
    expect = ttc((0, 0), 0.0, (10, 0), (15, -2), (0, 1.5), margin=cfg.vehicle_margin)
    assert float(sct[0]) == pytest.approx(expect, abs=0.02)


def test_speed_hypotheses_catch_a_pedestrian_who_stops_in_the_lane():
    # walking across the car's lane: at its own speed it is gone when the car arrives, but if
    # it stopped where it is (factor 0) the car would hit it after (10 - 2.2 - 0.3) / 10 s
    path = Path.of(np.array([[-100.0, 0.0], [100.0, 0.0]]))
    ped, vel = np.array([[10.0, 0.0]]), np.array([[0.0, 3.0]])
    for factors, expect in (((1.0,), math.inf), ((0.0, 1.0), 0.75)):
        cfg = SCTConfig(time_step=0.05, speed_factors=factors)
        xy, hd = path.at(100.0 + 10.0 * cfg.times)
        sct = safety_cushion_time(
            xy[None], hd[None], np.array([4.0]), np.array([2.0]), ped, vel, cfg
        )
        assert float(sct[0]) == pytest.approx(expect, abs=0.02)


@pytest.fixture(scope="module")
def geometry(tmp_path_factory) -> NetGeometry:
    out = tmp_path_factory.mktemp("sct_net") / "x.net.xml"
    return NetGeometry.from_net(build_intersection(out, IntersectionParams(traffic_light=False)))


def test_net_geometry_of_the_four_leg_intersection(geometry):
    assert len(geometry.crossings) == 4
    assert np.allclose(geometry.crossings.half_length, 3.5)  # two 3.5 m lanes
    straight = Path.of(geometry.path(("n_in", "s_out")))
    xs = straight.points[:, 0]
    assert np.allclose(xs, xs[0])  # a straight line down the right-hand lane
    assert straight.cum[-1] == pytest.approx(300.0, abs=1.0)
    turn = Path.of(geometry.path(("n_in", "w_out")))
    assert turn.cum[-1] < straight.cum[-1]


def _kerb_ped(geometry, heading, dist=0.8, speed=0.0):
    """A pedestrian ``dist`` m off the west edge of the north arm's carriageway."""
    k = geometry.kerbs
    cy = geometry.junction_xy[0, 1]
    west_edge = (k.crossing < 0) & np.isclose(k.inward[:, 0], 1.0) & (k.a[:, 1] > cy)
    edge_x = k.a[np.flatnonzero(west_edge)[0], 0]
    xy = np.array([[edge_x - dist, cy + 30.0]])
    return pedestrian_velocity(
        xy, np.array([heading]), np.array([speed]), np.array([True]), k, SCTConfig()
    )


def test_dart_out_for_a_pedestrian_facing_the_carriageway(geometry):
    vel, dart = _kerb_ped(geometry, heading=0.0)  # facing east, into the road
    assert dart[0]
    assert vel[0] == pytest.approx([1.3, 0.0])
    vel, dart = _kerb_ped(geometry, heading=math.pi)  # facing away
    assert not dart[0] and np.allclose(vel, 0.0)
    vel, dart = _kerb_ped(geometry, heading=0.0, dist=2.0)  # too far from the kerb
    assert not dart[0]


def test_no_dart_out_onto_a_crossing_that_is_closed(geometry):
    cr = geometry.crossings
    end = cr.centre[0] - cr.direction[0] * (cr.half_length[0] + 0.4)  # at one end, outside
    heading = math.atan2(cr.direction[0, 1], cr.direction[0, 0])  # facing along the crossing
    args = (end[None], np.array([heading]), np.zeros(1), np.array([True]), geometry.kerbs)
    _, dart = pedestrian_velocity(*args, SCTConfig())
    assert dart[0]
    closed = np.ones(len(cr), bool)
    closed[0] = False
    _, dart = pedestrian_velocity(*args, SCTConfig(), closed)
    assert not dart[0]


def test_crossing_conflict_zone():
    path = Path.of(np.array([[0.0, -50.0], [0.0, 50.0]]))  # car driving north along x = 0
    peds = np.array([[1.0, 10.0], [1.5, 10.0], [-0.5, 10.0]])
    u = np.tile([1.0, 0.0], (3, 1))  # crossing along x at y = 10
    centre, half = np.tile([0.0, 10.0], (3, 1)), np.full(3, 3.5)
    for s_car, car_in in ((60.0, True), (57.8, True), (57.6, False)):
        has, vin, pin = crossing_conflict(path, s_car, 4.0, 2.0, peds, u, centre, half, R)
        assert has.all()
        assert (vin == car_in).all()  # within 2 + 0.3 m of the zone along the path
        assert pin.tolist() == [True, False, True]  # within 1 + 0.3 m of the centre line


def test_post_encroachment_time_per_pair():
    pet = PostEncroachmentTracker(memory=3.0)
    key = [("v", "p")]
    ev = []
    for k in range(31):
        t = round(k * 0.1, 1)
        ped_in = t < 1.0
        car_in = t >= 1.6
        ev += pet.update(t, key, np.array([car_in]), np.array([ped_in]))
    assert [(e.vehicle, e.pedestrian) for e in ev] == [("v", "p")]
    assert ev[0].pet == pytest.approx(0.6)
    both = PostEncroachmentTracker().update(0.0, key, np.array([True]), np.array([True]))
    assert both[0].pet == 0.0
