"""Raw LiDAR in a recording: a real 64-channel scan written as hiyari.LidarScan, read back by
the mcap library and by Recording within the stated quantisation, decodable from the format
description alone, with a thinned foxglove.PointCloud for display; and recording a closed-loop
run does not change its results."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import zstandard
from google.protobuf.message import Message
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from runs import run_preset

from hiyari.bridge.loop.execute import RunOptions
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.bridge.record import lidar_scan
from hiyari.bridge.record.foxglove_convert import unpack_point_cloud
from hiyari.bridge.record.reader import Recording
from hiyari.bridge.record.recorder import Recorder, RecorderConfig
from hiyari.errors import HiyariError
from hiyari.sensors.environment.conditions import Environment
from hiyari.sensors.frames import Mount
from hiyari.sensors.lidar.config import LidarConfig
from hiyari.sensors.lidar.sensor import Lidar
from hiyari.sensors.outputs import HIT_NONE, HIT_STATIC, PointCloud
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, street_scenario

CREATED = "2026-01-01T00:00:00Z"


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[PointCloud]]:
    """Two 64 x 2,048 scans of the built-in street from a moving ego (moving actors, so the
    scan-time skew bends their points off the beams; rain, so some returns hit no surface)."""
    world = street_scenario(ego_speed=12.0)
    scene = RayScene(StraightRoad().mesh())
    scene.update(world, "ego")
    lidar = Lidar(LidarConfig.preset("64ch"), Mount(x=0.0, z=1.9), name="top")
    env = Environment(rain_mm_h=20.0)
    clouds = []
    for k in range(2):
        pc = lidar.scan(scene, world.pose_of("ego"), world, env, np.random.default_rng(k))
        clouds.append(dataclasses.replace(pc, time=0.1 * k))
    path = tmp_path_factory.mktemp("lidar") / "scan.mcap"
    with Recorder(path, {"scenario": "street"}, RecorderConfig(creation_time=CREATED)) as rec:
        for pc in clouds:
            rec.write_world(dataclasses.replace(world, time=pc.time), "ego")
            rec.write_point_cloud(pc)
    return path, clouds


def test_scan_reads_back_within_the_stated_quantisation(
    recorded: tuple[Path, list[PointCloud]],
) -> None:
    path, clouds = recorded
    rec = Recording.open(path)
    assert rec.lidar_sensors == ["top"]
    for i, orig in enumerate(clouds):
        hits = orig.hit
        assert len(orig) > 50_000 and (hits >= 0).any() and (hits == HIT_NONE).any()
        assert (hits == HIT_STATIC).any()
        back = rec.point_cloud_at("top", i)
        assert back.time == orig.time and len(back) == len(orig)
        np.testing.assert_array_equal(back.sensor_to_world, orig.sensor_to_world)
        np.testing.assert_array_equal(back.truth_ids(), orig.truth_ids())
        r = orig.range.astype(np.float64)
        dr = np.abs(back.range - r)
        assert dr.max() <= lidar_scan.RANGE_STEP_M / 2 + 1e-5
        assert dr.max() > 0.4 * lidar_scan.RANGE_STEP_M  # quantised, not stored as float32
        dxyz = np.linalg.norm(back.xyz.astype(np.float64) - orig.xyz, axis=1)
        bound = lidar_scan.RANGE_STEP_M / 2 + r * lidar_scan.ANGLE_STEP_RAD + 2e-5
        assert np.all(dxyz <= bound)
        dlog = np.abs(np.log2(back.intensity / orig.intensity))
        assert dlog.max() <= lidar_scan.LOG2_INTENSITY_STEP / 2 + 1e-6
    assert rec.point_cloud("top", len(rec) - 1).time == clouds[-1].time


def _decode_as_documented(msg: Message) -> tuple[np.ndarray, np.ndarray]:
    """(xyz, range) following format.py's description step by step (numpy + zstandard)."""
    n = msg.point_count
    raw = zstandard.ZstdDecompressor().decompress(msg.data)
    cols = []
    for c in range(5):
        planes = np.frombuffer(raw, np.uint8, 4 * n, 4 * n * c).reshape(4, n).astype(np.int64)
        z = planes[0] | planes[1] << 8 | planes[2] << 16 | planes[3] << 24
        cols.append(np.cumsum((z >> 1) ^ -(z & 1)))
    a, e, r = cols[0] * msg.angle_step_rad, cols[1] * msg.angle_step_rad, cols[2]
    rng = r * msg.range_step_m
    xyz = rng[:, None] * np.c_[np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)]
    return xyz, rng


def test_mcap_reader_decodes_the_scan_and_the_display_cloud(
    recorded: tuple[Path, list[PointCloud]],
) -> None:
    path, clouds = recorded
    rec = Recording.open(path)
    with path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        msgs = list(reader.iter_decoded_messages(topics=["/lidar/top", "/lidar/top/thinned"]))
    scans = [(ch, m) for _, ch, _, m in msgs if ch.topic == "/lidar/top"]
    shown = [(ch, m) for _, ch, _, m in msgs if ch.topic == "/lidar/top/thinned"]
    assert len(scans) == len(shown) == 2
    for (ch, msg), orig in zip(scans, clouds, strict=True):
        assert msg.DESCRIPTOR.full_name == "hiyari.LidarScan"
        assert ch.metadata["hiyari.display_topic"] == "/lidar/top/thinned"
        assert msg.timestamp_ns == round(orig.time * 1e9)
        assert msg.range_step_m == lidar_scan.RANGE_STEP_M
        # ~0.7 byte a point on a city scan (24 bytes as float32 fields before)
        assert len(msg.data) < 1.0 * len(orig)
        xyz, rng = _decode_as_documented(msg)
        back = rec.point_cloud_at("top", int(round(orig.time / 0.1)))
        np.testing.assert_allclose(xyz, back.xyz, atol=2e-5)
        np.testing.assert_allclose(rng, back.range, rtol=1e-7)
    every = RecorderConfig().lidar_display_every
    for (ch, msg), orig in zip(shown, clouds, strict=True):
        assert msg.DESCRIPTOR.full_name == "foxglove.PointCloud"
        assert ch.metadata["hiyari.thinning"].startswith(f"1 in {every} points")
        pts, pose = unpack_point_cloud(msg)
        assert len(pts) == math.ceil(len(orig) / every)
        assert pts["x"].tobytes() == orig.xyz[::every, 0].tobytes()
        np.testing.assert_array_equal(pts["intensity"], orig.intensity[::every])
        np.testing.assert_array_equal(pose, orig.sensor_to_world)


def test_bad_lidar_input_is_refused(
    tmp_path: Path, recorded: tuple[Path, list[PointCloud]]
) -> None:
    _, clouds = recorded
    with pytest.raises(HiyariError, match="lidar encoding"):
        RecorderConfig(lidar_encoding="float16").validate()
    with pytest.raises(HiyariError, match="thinning"):
        RecorderConfig(lidar_display_every=-1).validate()
    xyz = clouds[0].xyz.copy()
    xyz[3] = np.nan
    bad = dataclasses.replace(clouds[0], xyz=xyz)
    with Recorder(tmp_path / "bad.mcap", {}) as rec, pytest.raises(HiyariError, match="non-finite"):
        rec.write_point_cloud(bad)


def test_recording_a_closed_loop_run_does_not_change_it(tmp_path: Path) -> None:
    cs = ConcreteScenario(
        "dart-out",
        "dart-out",
        0,
        1,
        2.0,
        0.05,
        {"ve0_kmh": 40.0, "ped_speed_kmh": 5.0, "impact_fraction": 0.5},
        perception="sensors",
    )
    plain = run_preset(cs, RunOptions())
    recorded = run_preset(cs, RunOptions(out_dir=tmp_path, record=True))
    rec = Recording.open(tmp_path / "run.mcap")
    assert rec.lidar_sensors and len(rec.point_cloud("lidar", len(rec) - 1)) > 1000
    a, b = plain.series.columns(), recorded.series.columns()
    assert len(a["t"]) == len(b["t"]) > 10
    for name in a:
        np.testing.assert_array_equal(a[name], b[name], name)
    assert plain.detection.keys() == recorded.detection.keys()
    for source, stats in plain.detection.items():
        assert stats.as_dict() == recorded.detection[source].as_dict(), source
