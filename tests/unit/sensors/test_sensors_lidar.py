"""LiDAR physics: range and intensity of a flat target, occlusion, rain, black leather, noise, skew."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import DEFAULT_OPTICS, Material
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.detection_range import RangeStudy, RangeSweep
from hiyari.sensors.environment.atmosphere import AtmosphereModel
from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.environment.presets import PRESETS
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.outputs import HIT_NONE, HIT_STATIC
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import actor_world, quad, street_scenario, wall
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState

FIELDS = (
    "ids",
    "cls",
    "xyz",
    "heading",
    "speed",
    "accel",
    "length",
    "width",
    "height",
    "lane",
    "edge",
)

SENSOR_Z = 1.0


def one_channel(fov_deg: float = 60.0, columns: int = 61, **kw) -> LidarConfig:
    """A single horizontal channel over a sector, noise-free unless asked."""
    base = dict(
        rate_hz=10.0, max_range_m=200.0, min_range_m=0.5, range_10pct_m=50.0, range_noise_m=0.0
    )
    base.update(kw)
    return LidarConfig("test", (0.0,), columns, horizontal_fov_deg=fov_deg, **base)


def ego_only(speed: float = 0.0):
    world = actor_world([dict(id="ego", cls=ActorClass.CAR, x=0.0, y=0.0, speed=speed)])
    return world, world.pose_of("ego")


def scan(mesh: SceneMesh, config: LidarConfig, env=None, seed=0, world=None):
    world, ego = (world, world.pose_of("ego")) if world is not None else ego_only()
    scene = RayScene(mesh)
    scene.update(world, "ego")
    lidar = Lidar(config, Mount(x=0.0, z=SENSOR_Z))
    return lidar.scan(scene, ego, world, env or Environment(), np.random.default_rng(seed)), lidar


def test_flat_target_range_and_intensity_ratio():
    # a concrete wall facing the sensor 20 m ahead: range 20 / cos(az), intensity rho cos^3(az) / 20^2
    mesh = wall(20.0, -30.0, 30.0, 3.0, Material.CONCRETE)
    cloud, _ = scan(mesh, one_channel())
    az = np.arctan2(cloud.xyz[:, 1], cloud.xyz[:, 0])
    assert len(cloud) == 61
    np.testing.assert_allclose(cloud.range, 20.0 / np.cos(az), rtol=1e-5)
    rho = DEFAULT_OPTICS[Material.CONCRETE].lidar
    np.testing.assert_allclose(cloud.intensity, rho * np.cos(az) ** 3 / 400.0, rtol=1e-4)
    centre = np.argmin(np.abs(az))
    edge = np.argmax(np.abs(az))
    assert cloud.intensity[edge] / cloud.intensity[centre] == pytest.approx(
        math.cos(az[edge]) ** 3, rel=1e-4
    )
    assert np.all(cloud.hit == HIT_STATIC)
    # the same wall twice as far returns a quarter of the light
    far, _ = scan(
        wall(40.0, -30.0, 30.0, 3.0, Material.CONCRETE), one_channel(fov_deg=2.0, columns=1)
    )
    near, _ = scan(mesh, one_channel(fov_deg=2.0, columns=1))
    assert far.intensity[0] / near.intensity[0] == pytest.approx(0.25, rel=1e-4)


def test_target_behind_another_is_not_hit():
    front = wall(10.0, -2.0, 2.0, 3.0, Material.CONCRETE)
    back = wall(20.0, -30.0, 30.0, 3.0, Material.BUILDING)
    cloud, _ = scan(SceneMesh.concatenate([front, back]), one_channel())
    lateral = cloud.xyz[:, 1]
    shadow = np.abs(lateral / cloud.xyz[:, 0]) < 2.0 / 10.0 - 1e-3
    assert np.all(cloud.range[shadow] < 10.5)
    assert np.all(cloud.range[~shadow] > 19.9)
    # a car hidden behind a truck in the same lane gets no point
    world = actor_world(
        [
            dict(id="ego", cls=ActorClass.CAR, x=0.0, y=0.0),
            dict(id="truck", cls=ActorClass.TRUCK, x=15.0, y=0.0),
            dict(id="car", cls=ActorClass.CAR, x=30.0, y=0.0),
        ]
    )
    cfg = LidarConfig.preset("64ch").with_fov(40.0)
    cloud, _ = scan(SceneMesh.concatenate([]), cfg, world=world)
    ids = cloud.truth_ids()
    assert np.sum(ids == "truck") > 50
    assert np.sum(ids == "car") == 0


def detection_limit(config: LidarConfig, env: Environment, distances: np.ndarray) -> float:
    """Farthest wall distance that still returns the straight-ahead ray."""
    best = 0.0
    for d in distances:
        cloud, _ = scan(wall(float(d), -5.0, 5.0, 3.0, Material.ASPHALT), config, env)
        if len(cloud):
            best = float(d)
    return best


def test_rain_lowers_detection_range_monotonically():
    cfg = one_channel(fov_deg=1.0, columns=1, rain_ghost_per_mm_h=0.0)
    distances = np.arange(20.0, 60.0, 1.0)
    rates = [0.0, 10.0, 30.0, 100.0, 300.0]
    limits = [detection_limit(cfg, Environment(rain_mm_h=r), distances) for r in rates]
    assert all(a >= b for a, b in zip(limits, limits[1:], strict=False))
    assert limits[-1] < limits[0]
    # each limit matches the hand-solved threshold: 0.1 exp(-2 a r) / r^2 = 0.1 / 50^2
    atm = AtmosphereModel()
    for rate, limit in zip(rates, limits, strict=True):
        a = atm.lidar_extinction(Environment(rain_mm_h=rate))
        r = np.linspace(1, 60, 60000)
        solved = r[np.flatnonzero(np.exp(-2 * a * r) / r**2 >= 1 / 50.0**2)[-1]]
        assert limit == pytest.approx(math.floor(solved), abs=1.0)


def test_rain_ghosts_are_short_range_and_unlabelled():
    cfg = replace(LidarConfig.preset("32ch"), range_noise_m=0.0)
    mesh = wall(40.0, -60.0, 60.0, 10.0, Material.BUILDING)
    cloud, _ = scan(mesh, cfg, Environment(rain_mm_h=100.0), seed=3)
    ghosts = cloud.hit == HIT_NONE
    assert ghosts.sum() > 100
    assert np.all((cloud.range[ghosts] >= 7.0) & (cloud.range[ghosts] <= 15.0))
    dry, _ = scan(mesh, cfg, Environment(), seed=3)
    assert np.sum(dry.hit == HIT_NONE) == 0


def test_black_leather_cuts_detection_range_as_in_the_seed():
    # seed (divp-H 3.4 C): NCAP dummy far limit 35 m; black-leather jacket 22.5 m
    study = RangeStudy(distances_m=tuple(np.arange(17.5, 42.6, 2.5)))
    sweep = RangeSweep(study)
    normal = sweep.ranges("pedestrian", PRESETS["clear"])["lidar"]
    leather = sweep.ranges("pedestrian", PRESETS["dark_clothing"])["lidar"]
    assert normal == pytest.approx(35.0, abs=2.5)
    assert leather == pytest.approx(22.5, abs=2.5)
    assert leather < normal


def test_seeded_noise_is_reproducible():
    cfg = LidarConfig.preset("16ch")
    mesh = wall(30.0, -60.0, 60.0, 10.0, Material.BUILDING)
    a, _ = scan(mesh, cfg, Environment(rain_mm_h=20.0), seed=11)
    b, _ = scan(mesh, cfg, Environment(rain_mm_h=20.0), seed=11)
    c, _ = scan(mesh, cfg, Environment(rain_mm_h=20.0), seed=12)
    assert np.array_equal(a.xyz, b.xyz) and np.array_equal(a.intensity, b.intensity)
    assert np.array_equal(a.hit, b.hit)
    assert not np.array_equal(a.range, c.range)


def test_scan_time_skew_moves_points_of_moving_targets():
    cfg = replace(LidarConfig.preset("64ch").with_fov(30.0), range_noise_m=0.0)

    def cloud_for(speed: float):
        world = actor_world(
            [
                dict(id="ego", cls=ActorClass.CAR, x=0.0, y=0.0),
                dict(id="car", cls=ActorClass.CAR, x=20.0, y=0.0, heading=math.pi / 2, speed=speed),
            ]
        )
        cloud, lidar = scan(SceneMesh.concatenate([]), cfg, world=world)
        return cloud, lidar

    still, lidar = cloud_for(0.0)
    moving, _ = cloud_for(15.0)
    assert np.array_equal(still.hit, moving.hit)
    rows = np.flatnonzero(still.hit >= 0)
    assert len(rows) > 50
    # each point shifts by v * (time its column fired after the scan start), along +y
    step = math.radians(cfg.horizontal_fov_deg) / cfg.columns
    az = np.arctan2(still.xyz[rows, 1], still.xyz[rows, 0])
    column = np.round((math.radians(cfg.horizontal_fov_deg) / 2 - step / 2 - az) / step)
    fired = column / (cfg.columns * cfg.rate_hz)
    np.testing.assert_allclose(moving.xyz[rows, 1] - still.xyz[rows, 1], 15.0 * fired, atol=1e-4)
    np.testing.assert_allclose(moving.xyz[rows, 0], still.xyz[rows, 0], atol=1e-4)


def test_static_scene_is_not_rebuilt_by_updates():
    scene = RayScene(wall(20.0, -5.0, 5.0, 3.0, Material.CONCRETE))
    static = scene._static
    for x in (10.0, 12.0, 14.0):
        scene.update(
            actor_world(
                [
                    dict(id="ego", cls=ActorClass.CAR, x=0, y=0),
                    dict(id="p", cls=ActorClass.PEDESTRIAN, x=x, y=0),
                ]
            ),
            "ego",
        )
        assert scene._static is static
        assert len(scene.actors) == 30


@pytest.mark.parametrize(
    "change, message",
    [
        (dict(elevations_deg=()), "at least one channel"),
        (dict(columns=0), "columns"),
        (dict(min_range_m=50.0, max_range_m=10.0), "min_range_m < max_range_m"),
        (dict(rate_hz=0.0), "rate_hz"),
        (dict(horizontal_fov_deg=400.0), "horizontal_fov_deg"),
        (dict(elevations_deg=(95.0,)), "elevations"),
    ],
)
def test_impossible_lidar_parameters_are_rejected(change, message):
    with pytest.raises(HiyariError, match=message):
        Lidar(replace(LidarConfig.preset("16ch"), **change))


def test_unknown_lidar_preset_lists_known_ones():
    with pytest.raises(HiyariError, match="64ch"):
        LidarConfig.preset("65ch")


class _EveryRayScene(RayScene):
    """A scene that casts every ray into the actor scene (no pick by the actors' spheres)."""

    def cast(self, origins, directions, max_range, rays=None, normals=False, actors=True):
        return super().cast(origins, directions, max_range, None, normals, actors)


def test_rays_left_out_of_the_actor_cast_could_not_have_hit_an_actor():
    # the ego fast (its rays' origins move 2 m in a scan) and pedestrians close beside it,
    # whose small spheres the late rays of the scan see shifted by degrees; a truck and a car
    # close by and the street's actors around: the picked rays must give the scan of every ray
    world = street_scenario(occluder=True, ego_speed=20.0)
    near = [
        dict(id="truck_beside", cls=ActorClass.TRUCK, x=1.0, y=3.5, speed=25.0),
        dict(id="car_behind", cls=ActorClass.CAR, x=-9.0, y=-1.75, speed=21.0),
    ]
    near += [
        dict(id=f"walker{k}", cls=ActorClass.PEDESTRIAN, x=x, y=y, speed=1.0)
        for k, (x, y) in enumerate([(0.5, -6.0), (-3.0, -6.5), (4.0, -7.0), (-6.0, 6.0)])
    ]
    beside = actor_world(near)
    world = WorldState(
        world.time, *(np.concatenate([getattr(world, f), getattr(beside, f)]) for f in FIELDS)
    )
    ground = quad([(-150, -60, 0), (150, -60, 0), (150, 60, 0), (-150, 60, 0)], Material.ASPHALT)
    mesh = SceneMesh.concatenate([ground, wall(30.0, 4.0, 12.0, 3.0, Material.CONCRETE)])
    ego = world.pose_of("ego")
    lidar = Lidar(LidarConfig.preset("64ch"), Mount(x=0.0, z=1.9))
    clouds = []
    for scene in (RayScene(mesh), _EveryRayScene(mesh)):
        scene.update(world, "ego")
        clouds.append(lidar.scan(scene, ego, world, Environment(), np.random.default_rng(3)))
    picked, every = clouds
    assert (every.hit >= 0).sum() > 1000  # the actors are in the scan
    for f in ("xyz", "range", "intensity", "hit"):
        np.testing.assert_array_equal(getattr(picked, f), getattr(every, f))
