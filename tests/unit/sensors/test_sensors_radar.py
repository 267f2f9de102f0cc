"""Radar physics: 1/r^4 power, range rate = closing speed, rain loss, multipath ghosts."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import Material
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.environment.atmosphere import AtmosphereModel
from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.frames import Mount
from hiyari.sensors.outputs import HIT_NONE
from hiyari.sensors.radar.config import RadarConfig
from hiyari.sensors.radar.recognition import linked_groups, recognise_radar
from hiyari.sensors.radar.sensor import Radar
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, actor_world, box
from hiyari.traffic.actor_class import ActorClass

QUIET = replace(RadarConfig.preset("narrow"), false_alarms_per_cycle=0.0)


def car_ahead(distance: float, ego_speed: float = 0.0, car_speed: float = 0.0):
    return actor_world(
        [
            dict(id="ego", cls=ActorClass.CAR, x=0.0, y=0.0, speed=ego_speed),
            dict(id="car", cls=ActorClass.CAR, x=distance, y=0.0, speed=car_speed),
        ]
    )


def radar_scan(world, config=QUIET, env=None, mesh=None, seed=0):
    scene = RayScene(mesh if mesh is not None else SceneMesh.concatenate([]))
    scene.update(world, "ego")
    radar = Radar(config, Mount(x=2.25, z=0.5))
    ego = world.pose_of("ego")
    return radar.scan(scene, ego, world, env or Environment(), np.random.default_rng(seed))


def target_power_w(det, row: int = 1) -> float:
    m = det.hit == row
    return float(np.sum(10 ** ((det.power_dbm[m] - 30) / 10)))


def test_power_falls_as_inverse_fourth_power_of_range():
    ranges = np.array([15.0, 20.0, 30.0, 40.0, 60.0])
    power = np.array([target_power_w(radar_scan(car_ahead(d + 4.5))) for d in ranges])
    slope = np.polyfit(np.log10(ranges), 10 * np.log10(power), 1)[0]
    assert slope == pytest.approx(-40.0, abs=1.5)
    # and matches the radar equation with the car's rear RCS (10 dBsm) at boresight, less
    # up to 2 dB because the car shape fills ~80 % of its box and the pattern tapers
    expected = QUIET.radar_constant * 10.0 / ranges**4
    gap_db = 10 * np.log10(power / expected)
    assert np.all((gap_db < 0.1) & (gap_db > -2.0))


def test_range_rate_equals_closing_speed():
    det = radar_scan(car_ahead(40.0, ego_speed=15.0, car_speed=5.0))
    m = det.hit == 1
    assert m.sum() >= 1
    assert np.all(np.abs(det.range_rate[m] - (-10.0)) < 0.2)
    objects = recognise_radar(det)
    car = np.flatnonzero(objects.truth == "car")
    assert len(car) == 1
    assert objects.velocity[car[0], 0] == pytest.approx(-10.0, abs=0.2)
    # range is measured to the car's rear from the bumper-mounted sensor
    assert objects.position[car[0], 0] == pytest.approx(40.0 - 2.25 - 2.25, abs=0.5)


def test_rain_attenuation_is_two_way_itu_loss():
    clear = radar_scan(car_ahead(50.0))
    rain = radar_scan(car_ahead(50.0), env=Environment(rain_mm_h=50.0))
    a = AtmosphereModel().radar_attenuation_db_per_m(Environment(rain_mm_h=50.0))
    r = 50.0 - 4.5
    loss_db = 10 * np.log10(target_power_w(clear) / target_power_w(rain))
    assert loss_db == pytest.approx(2 * a * r, abs=0.1)
    assert loss_db > 1.0


def test_guard_rail_multipath_makes_a_ghost_beyond_the_target():
    rail = box((-10.0, 3.0, 0.0), (200.0, 3.2, 1.2), Material.BARRIER_METAL)
    world = actor_world(
        [
            dict(id="ego", cls=ActorClass.CAR, x=0.0, y=0.0),
            dict(id="car", cls=ActorClass.CAR, x=25.0, y=1.0),
        ]
    )
    cfg = replace(RadarConfig.preset("wide"), multipath=True, false_alarms_per_cycle=0.0)
    det = radar_scan(world, cfg, mesh=rail)
    direct = det.range[det.hit == 1]
    ghosts = det.range[det.hit == HIT_NONE]
    assert len(direct) and len(ghosts)
    assert ghosts.max() > direct.min() + 0.5
    plain = radar_scan(world, replace(cfg, multipath=False), mesh=rail)
    assert np.sum(plain.hit == HIT_NONE) == 0


def test_pedestrian_is_detected_closer_than_a_car():
    road = StraightRoad(buildings=False).mesh()
    ped = []
    car = []
    for d in (20.0, 40.0, 60.0, 80.0):
        w = actor_world(
            [
                dict(id="ego", cls=ActorClass.CAR, x=0, y=-1.75),
                dict(id="p", cls=ActorClass.PEDESTRIAN, x=d, y=-1.75, heading=math.pi / 2),
            ]
        )
        ped.append(np.any(radar_scan(w, mesh=road).hit == 1))
        car.append(np.any(radar_scan(car_ahead(d), mesh=road).hit == 1))
    assert car == [True, True, True, True]
    assert ped[0] and not ped[-1]


def test_seeded_radar_noise_is_reproducible():
    world = car_ahead(30.0, ego_speed=10.0)
    a, b = radar_scan(world, seed=4), radar_scan(world, seed=4)
    c = radar_scan(world, seed=5)
    assert np.array_equal(a.range, b.range) and np.array_equal(a.azimuth, b.azimuth)
    assert not np.array_equal(a.range, c.range)


@pytest.mark.parametrize(
    "change, message",
    [
        (dict(h_step_deg=-0.2), "h_step_deg"),
        (dict(h_fov_deg=200.0), "wider"),
        (dict(n_rx=0), "RX"),
        (dict(range_resolution_m=0.0), "range_resolution_m"),
    ],
)
def test_impossible_radar_parameters_are_rejected(change, message):
    with pytest.raises(HiyariError, match=message):
        Radar(replace(RadarConfig.preset("narrow"), **change))


def test_seed_ray_grids():
    narrow, wide = Radar(RadarConfig.preset("narrow")), Radar(RadarConfig.preset("wide"))
    assert len(narrow.directions) == 76 * 31  # 15 deg / 0.2 deg x 15 deg / 0.5 deg
    assert len(wide.directions) == 121 * 51  # 60 deg / 0.5 deg x 25 deg / 0.5 deg
    with pytest.raises(HiyariError, match="narrow"):
        RadarConfig.preset("medium")


def test_linked_groups_number_groups_as_scipy_does():
    rng = np.random.default_rng(11)
    for n in (0, 1, 7, 60):
        xyz = rng.uniform(-6.0, 6.0, (n, 3))
        xyz[:, 2] *= 0.1
        rate = rng.choice([-3.0, 0.0, 0.5, 4.0], n) + rng.normal(0.0, 0.3, n)
        count, group = linked_groups(xyz, rate, 2.5, 1.5)
        d = np.linalg.norm(xyz[:, None] - xyz[None], axis=2)
        i, j = np.nonzero((d < 2.5) & (np.abs(rate[:, None] - rate[None]) < 1.5))
        want = connected_components(coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n)), False)
        assert count == want[0]
        np.testing.assert_array_equal(group, want[1])
        if n == 60:
            assert 3 < count < 50  # some groups of several detections, some alone
