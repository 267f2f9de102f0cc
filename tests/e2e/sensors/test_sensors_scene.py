"""Scene, recognition, presets, rig scheduling, bad input and the ``hiyari sensors`` CLI."""

from __future__ import annotations

import csv

import cv2
import numpy as np
import pytest

from hiyari.bridge.cli.main import main
from hiyari.bridge.studies.report.perception.detection_range import write_table
from hiyari.errors import HiyariError
from hiyari.net.mesh.materials import Material
from hiyari.sensors.detection_range import RangeStudy, perception_table, table_markdown
from hiyari.sensors.environment.conditions import Environment, Soiling, SoilingSpot
from hiyari.sensors.environment.presets import PRESETS, disturbance_preset
from hiyari.sensors.frames import Mount, sensor_to_world
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.outputs import HIT_NONE, HIT_STATIC
from hiyari.sensors.radar.config import RadarConfig
from hiyari.sensors.radar.sensor import Radar
from hiyari.sensors.rig import SensorRig
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, actor_world, street_scenario, wall
from hiyari.traffic.actor_class import ActorClass


def test_cast_keeps_the_nearer_of_static_and_actor_hits():
    scene = RayScene(wall(30.0, -10.0, 10.0, 5.0, Material.BUILDING))
    world = actor_world(
        [
            dict(id="ego", cls=ActorClass.CAR, x=0, y=0),
            dict(id="car", cls=ActorClass.CAR, x=10.0, y=0),
        ]
    )
    scene.update(world, "ego")
    origins = np.array([[0, 0, 0.5], [0, 5.0, 0.5], [0, 0, 0.5]], np.float32)
    dirs = np.array([[1, 0, 0], [1, 0, 0], [-1, 0, 0]], np.float32)
    hits = scene.cast(origins, dirs, 100.0)
    assert hits.hit.tolist() == [1, HIT_STATIC, HIT_NONE]
    assert hits.distance[0] == pytest.approx(10.0 - 2.25, abs=1e-4)
    assert hits.distance[1] == pytest.approx(30.0, abs=1e-4)
    assert hits.material[0] == Material.VEHICLE_PAINT and hits.material[1] == Material.BUILDING
    assert hits.cos_incidence[:2] == pytest.approx([1.0, 1.0], abs=1e-5)
    with pytest.raises(HiyariError, match="ghost"):
        scene.update(world, "ghost")


def test_sensor_pose_from_mount_and_ego():
    world = actor_world([dict(id="ego", cls=ActorClass.CAR, x=10.0, y=5.0, heading=np.pi / 2)])
    ego = world.pose_of("ego")
    m = sensor_to_world(Mount(x=2.0, y=0.5, z=1.0, yaw_deg=90.0), ego)
    np.testing.assert_allclose(m[:3, 3], [10.0 - 0.5, 5.0 + 2.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(m[:3, 0], [-1.0, 0.0, 0.0], atol=1e-12)  # boresight points -x
    pitched = sensor_to_world(Mount(pitch_deg=10.0), ego)
    assert pitched[2, 0] == pytest.approx(-np.sin(np.radians(10.0)))  # positive pitch looks down
    with pytest.raises(HiyariError, match="nobody"):
        world.pose_of("nobody")


def test_lidar_and_radar_recognise_the_street_actors():
    scene = RayScene(StraightRoad().mesh())
    world = street_scenario()
    scene.update(world, "ego")
    ego = world.pose_of("ego")
    rng = np.random.default_rng(0)
    _, lidar_objects = Lidar(LidarConfig.preset("64ch")).sense(
        scene, ego, world, Environment(), rng
    )
    found = set(lidar_objects.truth)
    assert {"lead", "pedestrian", "cyclist", "oncoming"} <= found
    lead = np.flatnonzero(lidar_objects.truth == "lead")[0]
    assert lidar_objects.cls[lead] == ActorClass.CAR
    # only the lead car's rear is visible; its oriented box, completed to a car's length away
    # from the sensor, puts it at its centre 35 m ahead (the visible rear is at 32.75 m)
    assert lidar_objects.position[lead, 0] == pytest.approx(35.0, abs=0.3)
    ped = np.flatnonzero(lidar_objects.truth == "pedestrian")[0]
    assert lidar_objects.cls[ped] == ActorClass.PEDESTRIAN
    _, radar_objects = Radar(RadarConfig.preset("narrow")).sense(
        scene, ego, world, Environment(), rng
    )
    lead = np.flatnonzero(radar_objects.truth == "lead")
    assert len(lead) == 1
    # the lead drives 6 m/s, the ego 8 m/s: closing at 2 m/s
    assert radar_objects.velocity[lead[0], 0] == pytest.approx(-2.0, abs=0.3)


def test_rig_fires_each_sensor_at_its_rate():
    rig = SensorRig.default()
    counts = {s.name: 0 for s in rig.sensors}
    step = 0.01
    for k in range(1, 101):
        for s in rig.due(k * step, step):
            counts[s.name] += 1
    assert counts == {"lidar": 10, "radar": 20, "camera": 30}
    # one step of the rig: every sensor gives its raw output (no picture unless asked) and objects
    scene = RayScene(StraightRoad().mesh())
    world = street_scenario()
    scene.update(world, "ego")
    ego = world.pose_of("ego")
    rng = np.random.default_rng(0)
    out = {s.name: rig.sense(s, scene, ego, world, Environment(), rng) for s in rig.sensors}
    assert out["camera"][0] is None and len(out["lidar"][0]) > 1000 and len(out["radar"][0]) > 0
    assert all("lead" in objects.truth for _, objects in out.values())
    rig.render_images = True
    frame, _ = rig.sense(rig.sensors[2], scene, ego, world, Environment(), rng)
    assert frame.image.shape == (270, 480, 3)
    # rendering a picture (a recorded run) leaves the detections' random stream as it was:
    # recording a run must not change its results
    streams = []
    for render in (False, True):
        rig.render_images = render
        rng = np.random.default_rng(7)
        rig.sense(rig.sensors[2], scene, ego, world, Environment(), rng)
        streams.append(rng.random(4))
    assert np.array_equal(*streams)


def test_presets_and_environment_validation():
    assert disturbance_preset("dark_clothing").appearance.clothing == Material.DARK_CLOTHING
    env = PRESETS["backlight"].environment_for(np.pi / 2)
    assert env.sun_azimuth_deg == pytest.approx(90.0) and env.sun_elevation_deg == 5.0
    with pytest.raises(HiyariError, match="known: clear"):
        disturbance_preset("snow")
    for bad, message in [
        (dict(rain_mm_h=-1.0), "rain_mm_h"),
        (dict(fog_visibility_m=0.0), "fog_visibility_m"),
        (dict(sun_elevation_deg=120.0), "sun_elevation_deg"),
        (dict(illumination="twilight"), "illumination"),
    ]:
        with pytest.raises(HiyariError, match=message):
            Environment(**bad)
    with pytest.raises(HiyariError, match="uniform_transmission"):
        Soiling(uniform_transmission=1.5)
    with pytest.raises(HiyariError, match="radius"):
        Soiling(spots=(SoilingSpot(0, 0, -1.0),))


def test_perception_table_rows_and_files(tmp_path):
    study = RangeStudy(distances_m=(10.0, 30.0, 60.0))
    rows = perception_table(["clear", "fog"], ("car",), study, progress=False)
    assert [r["preset"] for r in rows] == ["clear", "fog"]
    clear, fog = rows
    assert fog["lidar_m"] < clear["lidar_m"] and fog["camera_m"] <= clear["camera_m"]
    assert fog["radar_m"] == clear["radar_m"]  # 77 GHz sees through fog
    paths = write_table(rows, tmp_path)
    with open(paths["csv"]) as f:
        back = list(csv.DictReader(f))
    assert float(back[1]["lidar_m"]) == fog["lidar_m"]
    assert "| fog |" in paths["md"].read_text() and "| fog |" in table_markdown(rows)
    assert cv2.imread(str(paths["png"])) is not None
    with pytest.raises(HiyariError, match="unknown disturbance preset"):
        perception_table(["hail"], progress=False)


@pytest.mark.parametrize("sensor", ["lidar", "radar", "camera"])
def test_cli_render_builtin_scene(sensor, tmp_path, capsys):
    assert (
        main(["sensors", "render", "--sensor", sensor, "--preset", "rain", "--out", str(tmp_path)])
        == 0
    )
    printed = capsys.readouterr().out
    files = sorted(p.name for p in tmp_path.iterdir())
    assert all(name in printed for name in files)
    png = [p for p in tmp_path.iterdir() if p.suffix == ".png"]
    assert png and all(cv2.imread(str(p)) is not None for p in png)
    with open(tmp_path / f"{sensor}_objects.csv") as f:
        truth = [row["truth"] for row in csv.DictReader(f)]
    assert "lead" in truth or "pedestrian" in truth
    if sensor == "lidar":
        with np.load(tmp_path / "lidar_points.npz") as data:
            assert data["xyz"].shape[1] == 3 and len(data["truth"]) == len(data["range"])
            assert np.any(data["hit"] == HIT_NONE)  # rain ghosts


def test_cli_render_on_a_sumo_network(intersection_net, tmp_path, capsys):
    code = main(
        [
            "sensors",
            "render",
            "--sensor",
            "radar",
            "--net",
            str(intersection_net),
            "--time",
            "40",
            "--vph",
            "2400",
            "--pph",
            "600",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    with open(tmp_path / "radar_detections.csv") as f:
        rows = list(csv.DictReader(f))
    assert rows and any(r["truth"] not in ("", "static") for r in rows)


def test_cli_bad_input_is_one_line(tmp_path, capsys):
    assert main(["sensors", "render", "--preset", "blizzard", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err.strip()
    assert (
        err.startswith("hiyari: error: unknown disturbance preset 'blizzard'") and "\n" not in err
    )
    assert main(["sensors", "render", "--sensor", "sonar", "--out", str(tmp_path)]) == 1
    assert "unknown sensor 'sonar'" in capsys.readouterr().err
    assert (
        main(
            [
                "sensors",
                "render",
                "--camera",
                "fisheye",
                "--sensor",
                "camera",
                "--out",
                str(tmp_path),
            ]
        )
        == 1
    )
    assert "unknown camera preset" in capsys.readouterr().err
