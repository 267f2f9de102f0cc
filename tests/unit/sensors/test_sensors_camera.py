"""Camera: projection, night / headlights / dark clothing, range error, occlusion, rendering."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import Material
from hiyari.sensors.camera.config import CameraConfig
from hiyari.sensors.camera.sensor import Camera
from hiyari.sensors.environment.conditions import Environment, Illumination
from hiyari.sensors.environment.presets import PRESETS
from hiyari.sensors.frames import Mount
from hiyari.sensors.scene.actor_shapes import ActorAppearance
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, actor_world
from hiyari.traffic.actor_class import ActorClass

LANE = -1.75


@pytest.fixture(scope="module")
def road() -> RayScene:
    return RayScene(StraightRoad().mesh())


def pedestrian_at(d: float, occluder: bool = False):
    actors = [
        dict(id="ego", cls=ActorClass.CAR, x=0.0, y=LANE),
        dict(id="ped", cls=ActorClass.PEDESTRIAN, x=d, y=LANE, heading=math.pi / 2),
    ]
    if occluder:
        actors.append(dict(id="truck", cls=ActorClass.TRUCK, x=d - 6.0, y=LANE))
    return actor_world(actors)


def detection_range(scene: RayScene, camera: Camera, env: Environment, clothing: Material) -> float:
    scene.set_appearance(ActorAppearance(clothing=clothing))
    best = 0.0
    for d in np.arange(5.0, 100.0, 2.5):
        world = pedestrian_at(float(d))
        scene.update(world, "ego")
        view = camera.view(scene, world.pose_of("ego"), world, env)
        if np.any(view.probability[world.ids[view.rows] == "ped"] >= 0.5):
            best = float(d)
    return best


def test_projection_round_trip_with_distortion():
    cfg = CameraConfig.preset("wide")
    u = np.array([0.0, 100.0, 960.0, 1500.0, 1919.0])
    v = np.array([0.0, 900.0, 540.0, 100.0, 1079.0])
    uv, front = cfg.project(cfg.pixel_rays(u, v) * 7.0)
    assert front.all()
    np.testing.assert_allclose(uv, np.stack([u, v], 1), atol=1e-6)
    # barrel distortion: the horizontal edge of the 120 deg view lands on the image edge
    edge = np.array([[1.0, -math.tan(math.radians(60)), 0.0]])
    assert cfg.project(edge)[0][0, 0] == pytest.approx(1920.0, abs=1e-6)


def test_dark_clothed_pedestrian_night_range_shrinks_and_headlights_restore_it(road):
    cam = Camera(CameraConfig.preset("wide"), Mount(x=0.8, z=1.3))
    night = Environment(illumination=Illumination.NIGHT)
    day = detection_range(road, cam, Environment(), Material.DARK_CLOTHING)
    dark_night = detection_range(road, cam, night, Material.DARK_CLOTHING)
    dark_lit = detection_range(
        road,
        cam,
        Environment(illumination=Illumination.NIGHT, headlights=True),
        Material.DARK_CLOTHING,
    )
    normal_lit = detection_range(
        road, cam, Environment(illumination=Illumination.NIGHT, headlights=True), Material.CLOTHING
    )
    assert dark_night < 0.25 * day
    assert dark_lit > dark_night + 20.0
    assert dark_lit <= normal_lit <= day + 2.5


def test_camera_range_error_grows_with_distance(road):
    cam = Camera(CameraConfig.preset("wide"), Mount(x=0.8, z=1.3))
    road.set_appearance(ActorAppearance())
    errors = {}
    for d in (15.0, 45.0):
        world = pedestrian_at(d)
        road.update(world, "ego")
        ego = world.pose_of("ego")
        rng = np.random.default_rng(0)
        err = []
        for _ in range(300):
            objects = cam.detect(road, ego, world, Environment(), rng)
            hit = objects.truth == "ped"
            truth = np.linalg.norm([d - 0.8, 0.0, 1.719 / 2 - 1.3])
            err += list(np.linalg.norm(objects.position[hit], axis=1) - truth)
        errors[d] = np.std(err)
    assert errors[45.0] > 2.5 * errors[15.0]


def test_occluded_pedestrian_is_not_seen(road):
    cam = Camera(CameraConfig.preset("wide"), Mount(x=0.8, z=1.3))
    road.set_appearance(ActorAppearance())
    for occluder, expect_seen in ((False, True), (True, False)):
        world = pedestrian_at(20.0, occluder)
        road.update(world, "ego")
        view = cam.view(road, world.pose_of("ego"), world, Environment())
        ped = world.ids[view.rows] == "ped"
        assert (view.probability[ped][0] > 0.9) == expect_seen
        assert (view.visible[ped][0] == 0.0) == (not expect_seen)


def test_presets_change_the_rendered_image(road):
    cam = Camera(
        CameraConfig.preset("wide").__class__("small", 640, 360, 120.0, render_width_px=160),
        Mount(x=0.8, z=1.3),
    )
    world = pedestrian_at(20.0)
    road.set_appearance(ActorAppearance())
    road.update(world, "ego")
    ego = world.pose_of("ego")

    def frame(name: str):
        return cam.render(
            road, ego, world, PRESETS[name].environment_for(0.0), np.random.default_rng(0)
        )

    clear, fog, night = frame("clear"), frame("fog"), frame("night")
    assert clear.image.shape == (90, 160, 3) and clear.image.dtype == np.uint8
    assert clear.intrinsics[0, 0] == pytest.approx(cam.config.fx * 160 / 640)
    # fog washes out the far scene around the horizon; an unlit night is dark
    band = slice(35, 55)
    assert fog.image[band].std() < 0.3 * clear.image[band].std()
    assert night.image.mean() < 0.5 * clear.image.mean()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(horizontal_fov_deg=190.0), "horizontal_fov_deg"),
        (dict(k1=-0.3), "folds over"),
        (dict(width_px=8), "at least 16"),
        (dict(rate_hz=0.0), "rate_hz"),
    ],
)
def test_impossible_camera_parameters_are_rejected(kwargs, message):
    base = dict(name="x", width_px=1920, height_px=1080, horizontal_fov_deg=120.0)
    base.update(kwargs)
    with pytest.raises(HiyariError, match=message):
        Camera(CameraConfig(**base))
