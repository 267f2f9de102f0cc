"""A recorded SUMO run read back with the MCAP reader, the ASAM OSI trace readers and
hiyari's Recording: frames, timestamps, actor ids and poses, and every sensor output."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.writer import Writer
from mcap_protobuf.decoder import DecoderFactory
from osi3trace.osi_trace import OSITrace
from osi_utilities import MessageType, MultiTraceReader
from osi_utilities.tracefile._config import (
    OSI_CHANNEL_REQUIRED_METADATA_KEYS,
    OSI_TRACE_REQUIRED_METADATA_KEYS,
)
from recording_data import CREATED, RecordedRun, record_run

from hiyari.bridge.cli.main import main
from hiyari.bridge.record.osi_convert import world_state_from_ground_truth
from hiyari.bridge.record.reader import Recording
from hiyari.bridge.record.recorder import Recorder, RecorderConfig
from hiyari.errors import HiyariError
from hiyari.traffic import ActorClass, SimConfig, Simulation, WorldState

GT = "/osi/ground_truth"
DURATION = 40.0


@pytest.fixture(scope="module")
def run(
    intersection_net: Path, intersection_demand: Path, tmp_path_factory: pytest.TempPathFactory
) -> RecordedRun:
    out = tmp_path_factory.mktemp("recording") / "run.mcap"
    # LiDAR as float32 foxglove.PointCloud, the bit-exact encoding these tests check; the
    # compact default (hiyari.LidarScan) is checked in test_recording_lidar.py
    cfg = RecorderConfig(camera_format="png", creation_time=CREATED, lidar_encoding="float32")
    return record_run(intersection_net, intersection_demand, out, DURATION, cfg)


@pytest.fixture(scope="module")
def rec(run: RecordedRun) -> Recording:
    return Recording.open(run.path)


def _ns(t: float) -> int:
    return int(round(t * 1e9))


def test_close_renames_part_file(run: RecordedRun) -> None:
    assert run.path.is_file()
    assert not run.path.with_name(run.path.name + ".part").exists()
    assert len(run.states) == round(DURATION / 0.1)


def test_mcap_reader_reads_frames_ids_and_poses(run: RecordedRun) -> None:
    with run.path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        schema_of = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
        decoded = [
            (msg.log_time, gt)
            for _, _, msg, gt in reader.iter_decoded_messages(topics=[GT], log_time_order=True)
        ]
    assert schema_of[GT] == "osi3.GroundTruth"
    assert schema_of["/osi/sensor_data/fusion"] == "osi3.SensorData"
    assert schema_of["/lidar/top"] == "foxglove.PointCloud"
    assert schema_of["/radar/front"] == "foxglove.PointCloud"
    assert schema_of["/camera/front/image"] == "foxglove.CompressedImage"
    assert schema_of["/camera/front/calibration"] == "foxglove.CameraCalibration"
    assert schema_of["/markers/ground_truth"] == "foxglove.SceneUpdate"
    assert schema_of["/markers/road_mesh"] == "foxglove.SceneUpdate"
    assert len(decoded) == len(run.states)
    for (log_time, gt), state in zip(decoded, run.states, strict=True):
        assert log_time == _ns(state.time)
        ids = [m.source_reference[0].identifier[0] for m in gt.moving_object]
        assert ids == state.ids.tolist()
        pos = np.array(
            [[m.base.position.x, m.base.position.y, m.base.position.z] for m in gt.moving_object]
        ).reshape(-1, 3)
        np.testing.assert_array_equal(pos[:, :2], state.xyz[:, :2])
        # OSI positions are bounding-box centres
        np.testing.assert_allclose(pos[:, 2], state.xyz[:, 2] + state.height / 2, atol=1e-12)
        yaw = np.array([m.base.orientation.yaw for m in gt.moving_object])
        np.testing.assert_array_equal(yaw, state.heading)


def test_osi_trace_readers_read_ground_truth_and_object_lists(run: RecordedRun) -> None:
    reader = MultiTraceReader()
    assert reader.open(run.path)
    try:
        meta = {m["name"]: m["data"] for m in reader.get_file_metadata()}
        assert OSI_TRACE_REQUIRED_METADATA_KEYS <= meta["net.asam.osi.trace"].keys()
        specs = {s.topic: s for s in reader.list_channel_specifications()}
        assert specs[GT].message_type == MessageType.GROUND_TRUTH
        assert specs["/osi/sensor_data/fusion"].message_type == MessageType.SENSOR_DATA
        for spec in specs.values():
            assert OSI_CHANNEL_REQUIRED_METADATA_KEYS <= spec.metadata.keys()
        reader.set_topics([GT])
        messages = [r.message for r in reader]
    finally:
        reader.close()
    assert len(messages) == len(run.states)
    for gt, state, ego in zip(messages, run.states, run.ego, strict=True):
        assert gt.timestamp.seconds * 10**9 + gt.timestamp.nanos == _ns(state.time)
        back, back_ego = world_state_from_ground_truth(gt)
        assert back.ids.tolist() == state.ids.tolist()
        assert back_ego == ego
        np.testing.assert_array_equal(back.xyz[:, :2], state.xyz[:, :2])
        np.testing.assert_array_equal(back.cls, state.cls)
    fusion = [o for o in run.objects if o.source == "fusion"]
    trace = OSITrace(str(run.path), "SensorData", topic="/osi/sensor_data/fusion")
    try:
        sensor_data = list(trace)
    finally:
        trace.close()
    assert len(sensor_data) == len(fusion)
    first, sd = fusion[0], sensor_data[0]
    assert [d.header.tracking_id.value for d in sd.moving_object] == first.object_id.tolist()
    assert len([d for d in sd.moving_object if d.header.ground_truth_id]) == int(
        np.sum(first.truth != "")
    )


def test_recording_reads_back_every_world_state(run: RecordedRun, rec: Recording) -> None:
    assert rec.complete and rec.problem is None
    assert len(rec) == len(run.states)
    np.testing.assert_array_equal(rec.times, [s.time for s in run.states])
    for k, state in enumerate(run.states):
        back, ego = rec.world_and_ego(k)
        assert ego == run.ego[k]
        assert back.time == state.time
        for name in ("ids", "cls", "heading", "length", "width", "height", "lane", "edge"):
            np.testing.assert_array_equal(getattr(back, name), getattr(state, name), name)
        np.testing.assert_array_equal(back.xyz[:, :2], state.xyz[:, :2])
        np.testing.assert_allclose(back.xyz[:, 2], state.xyz[:, 2], atol=1e-12)
        np.testing.assert_allclose(back.speed, state.speed, atol=1e-12)
        np.testing.assert_allclose(back.accel, state.accel, atol=1e-12)
    assert {ActorClass.CAR, ActorClass.PEDESTRIAN} <= set(np.unique(rec.world(-1).cls).tolist())


def test_metadata_environment_and_mesh(run: RecordedRun, rec: Recording) -> None:
    assert rec.metadata["scenario"] == "test intersection"
    assert rec.metadata["seed"] == "3"
    assert rec.metadata["format"] == "hiyari-recording"
    assert json.loads(rec.metadata["sensors"]) == ["top", "front"]
    assert json.loads(rec.sensor_configs["top"]) == {"kind": "lidar", "channels": 16}
    assert rec.osi_metadata["creation_time"] == CREATED
    # 3 mm/h, 500 m visibility, 300 lux in OSI's bands
    assert rec.environment(0) == {
        "precipitation": "moderate",
        "fog": "light",
        "ambient_illumination": "level6",
    }
    mesh = rec.mesh()
    np.testing.assert_array_equal(mesh.vertices, run.mesh.vertices)
    np.testing.assert_array_equal(mesh.faces, run.mesh.faces)
    np.testing.assert_array_equal(mesh.material, run.mesh.material)


def test_lidar_frames_round_trip_exactly(run: RecordedRun, rec: Recording) -> None:
    assert len(rec.message_times("/lidar/top")) == len(run.lidar)
    for i in (0, len(run.lidar) // 2, len(run.lidar) - 1):
        pc, orig = rec.point_cloud_at("top", i), run.lidar[i]
        assert pc.time == orig.time
        assert pc.xyz.dtype == np.float32
        assert pc.xyz.tobytes() == orig.xyz.tobytes()
        assert pc.intensity.tobytes() == orig.intensity.tobytes()
        assert pc.range.tobytes() == orig.range.tobytes()
        np.testing.assert_array_equal(pc.truth_ids(), orig.truth_ids())
        np.testing.assert_allclose(pc.sensor_to_world, orig.sensor_to_world, atol=1e-12)
    k = rec.frame_at(run.lidar[-1].time)
    assert rec.point_cloud("top", k).time == run.lidar[-1].time


def test_radar_objects_camera_and_status_round_trip(run: RecordedRun, rec: Recording) -> None:
    i = len(run.radar) // 2
    det, orig = rec.radar_at("front", i), run.radar[i]
    for name in ("range", "range_rate", "azimuth", "elevation", "snr_db", "power_dbm"):
        np.testing.assert_array_equal(getattr(det, name), getattr(orig, name), name)
    assert [det.actor_ids[h] if h >= 0 else h for h in det.hit] == [
        orig.actor_ids[h] if h >= 0 else h for h in orig.hit
    ]
    fusion = [o for o in run.objects if o.source == "fusion"]
    objs, orig = rec.objects_at("fusion", len(fusion) - 1), fusion[-1]
    for name in ("object_id", "cls", "position", "velocity", "size", "confidence", "truth"):
        np.testing.assert_array_equal(getattr(objs, name), getattr(orig, name), name)
    np.testing.assert_allclose(objs.frame_to_world, orig.frame_to_world, atol=1e-12)
    assert rec.object_sources == ["fusion", "radar"]
    cam, orig = rec.camera_at("front", 3), run.camera[3]
    np.testing.assert_array_equal(cam.image, orig.image)  # PNG: lossless
    np.testing.assert_array_equal(cam.intrinsics, orig.intrinsics)
    np.testing.assert_array_equal(cam.distortion, orig.distortion)
    np.testing.assert_allclose(cam.sensor_to_world, orig.sensor_to_world, atol=1e-12)
    t, speed, ttc, aeb, accel = run.status[-1]
    status = rec.ego_status(rec.frame_at(t))
    assert status["time"] == t and status["speed_mps"] == speed
    assert status["aeb_state"] == aeb and status["accel_cmd_mps2"] == accel
    assert status["ttc_s"] == (ttc if math.isfinite(ttc) else None)


def test_collisions_round_trip(run: RecordedRun, rec: Recording) -> None:
    first: dict[tuple[str, str], float] = {}
    for c in run.collisions:
        first.setdefault((c.a, c.b), c.time)
    back = {(c["a"], c["b"]): c["time"] for c in rec.collisions_until(len(rec) - 1)}
    assert back == first


# ---------------------------------------------------------------------- determinism
def _state(t: float, n: int) -> WorldState:
    k = np.arange(n, dtype=float)
    return WorldState(
        t,
        np.array([f"v{i}" for i in range(n)], dtype=object),
        np.zeros(n, np.int8),
        np.c_[k * 5 + t, k, np.zeros(n)],
        np.full(n, 0.3),
        np.full(n, 10.0),
        np.zeros(n),
        np.full(n, 4.5),
        np.full(n, 1.8),
        np.full(n, 1.5),
        np.full(n, "e_0", dtype=object),
        np.full(n, "e", dtype=object),
    )


def _write(path: Path, seed: int) -> None:
    cfg = RecorderConfig(creation_time=CREATED, flush_interval_s=0.3)
    with Recorder(path, {"scenario": "unit", "seed": seed}, cfg) as rec:
        for k in range(1, 30):
            rec.write_world(_state(0.1 * k, 3 + k % 4), ego_id="v0")


def test_same_input_gives_identical_file(tmp_path: Path) -> None:
    _write(tmp_path / "a.mcap", 1)
    _write(tmp_path / "b.mcap", 1)
    _write(tmp_path / "c.mcap", 2)
    a = (tmp_path / "a.mcap").read_bytes()
    assert a == (tmp_path / "b.mcap").read_bytes()
    assert a != (tmp_path / "c.mcap").read_bytes()


# ---------------------------------------------------------------------- crash safety
CRASH_SCRIPT = """
import sys
from pathlib import Path
from hiyari.bridge.record.recorder import Recorder, RecorderConfig
from hiyari.traffic import SimConfig, Simulation
net, routes, out = map(Path, sys.argv[1:4])
with Simulation(SimConfig(net=net, routes=[routes], seed=3)) as sim:
    rec = Recorder(out, {"scenario": "crash"}, RecorderConfig(flush_interval_s=0.5))
    for state in sim.run(until=3000.0):
        rec.write_world(state)
        if round(state.time * 10) % 10 == 0:
            print(f"{state.time:.1f}", flush=True)
"""


def test_killed_run_leaves_readable_part_file(
    intersection_net: Path, intersection_demand: Path, tmp_path: Path
) -> None:
    out = tmp_path / "crash.mcap"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-c",
            CRASH_SCRIPT,
            str(intersection_net),
            str(intersection_demand),
            str(out),
        ],
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "TMPDIR": str(tmp_path)},  # SIGKILL leaves SUMO's temporary folder
    )
    watchdog = threading.Timer(90.0, proc.kill)
    watchdog.start()
    reached = 0.0
    try:
        for line in proc.stdout:
            reached = float(line)
            if reached >= 20.0:
                os.kill(proc.pid, signal.SIGKILL)
                break
    finally:
        proc.wait()
        watchdog.cancel()
    assert reached >= 20.0 and proc.returncode == -signal.SIGKILL
    part = out.with_name("crash.mcap.part")
    assert not out.exists() and part.is_file()
    with pytest.raises(HiyariError, match=r"crash\.mcap\.part is an unfinished recording"):
        Recording.open(out)
    rec = Recording.open(part)
    assert not rec.complete and "incomplete" in rec.problem
    # everything up to 0.5 s before the last reported time was flushed
    assert rec.times[-1] >= 19.5 - 1e-9
    np.testing.assert_allclose(np.diff(rec.times), 0.1, atol=1e-9)
    # a finished copy for the readers that need the summary section (OSI trace readers)
    fixed = tmp_path / "recovered.mcap"
    assert main(["replay", str(part), "--recover", str(fixed)]) == 0
    reader = MultiTraceReader()
    assert reader.open(fixed)
    reader.set_topics([GT])
    stamps = [r.message.timestamp.seconds * 10**9 + r.message.timestamp.nanos for r in reader]
    reader.close()
    assert stamps == [int(round(t * 1e9)) for t in rec.times]
    assert Recording.open(fixed).complete
    last = rec.world(len(rec) - 1)
    with Simulation(SimConfig(net=intersection_net, routes=[intersection_demand], seed=3)) as sim:
        for _ in sim.run(until=last.time):
            pass
        state = sim.state
    assert state.time == last.time
    np.testing.assert_array_equal(last.ids, state.ids)
    np.testing.assert_array_equal(last.xyz[:, :2], state.xyz[:, :2])


def test_exception_in_run_keeps_part_name(tmp_path: Path) -> None:
    path = tmp_path / "failed.mcap"
    with pytest.raises(RuntimeError), Recorder(path, {"scenario": "x"}) as rec:
        rec.write_world(_state(0.1, 2))
        raise RuntimeError("controller crashed")
    assert not path.exists()
    back = Recording.open(path.with_name("failed.mcap.part"))
    assert len(back) == 1 and "unfinished" in back.problem


# ---------------------------------------------------------------------- bad input
def test_not_mcap(tmp_path: Path) -> None:
    bad = tmp_path / "notes.mcap"
    bad.write_text("hello, this is text\n")
    with pytest.raises(HiyariError, match=r"notes\.mcap: not an MCAP file"):
        Recording.open(bad)


def test_truncated_file_opens_up_to_last_complete_chunk(
    run: RecordedRun, rec: Recording, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = run.path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    back = Recording.open(cut)
    assert not back.complete
    assert "cut.mcap is incomplete" in back.problem and "frames up to" in back.problem
    assert 0 < len(back) < len(rec)
    np.testing.assert_array_equal(back.times, rec.times[: len(back)])
    np.testing.assert_array_equal(back.world(len(back) - 1).ids, rec.world(len(back) - 1).ids)
    html = tmp_path / "cut.html"
    assert main(["replay", str(cut), "--export", str(html), "--every", "50", "-q"]) == 0
    err = capsys.readouterr().err
    assert err.startswith("hiyari: warning: cut.mcap is incomplete") and html.is_file()
    stub = tmp_path / "stub.mcap"
    stub.write_bytes(data[:300])
    with pytest.raises(HiyariError, match=r"stub\.mcap: the recording holds no complete frame"):
        Recording.open(stub)


def test_mcap_from_another_program(tmp_path: Path) -> None:
    other = tmp_path / "other.mcap"
    with other.open("wb") as f:
        w = Writer(f)
        w.start(profile="", library="someone else")
        sid = w.register_schema("Pose", "jsonschema", b"{}")
        cid = w.register_channel("/robot/pose", "json", sid)
        w.add_message(cid, log_time=1, data=b'{"x": 1}', publish_time=1)
        w.finish()
    with pytest.raises(HiyariError, match=r"not a hiyari recording .*topics: /robot/pose"):
        Recording.open(other)


def test_cli_reports_bad_recordings_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "x.mcap"
    bad.write_bytes(b"\x00" * 64)
    assert main(["replay", str(bad)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hiyari: error:") and "not an MCAP file" in err[0]
    assert main(["replay", str(tmp_path / "missing.mcap")]) == 1
    assert "no such recording" in capsys.readouterr().err


def test_recorder_rejects_bad_parameters(tmp_path: Path) -> None:
    with pytest.raises(HiyariError, match=r"must end in \.mcap"):
        Recorder(tmp_path / "run.txt")
    with pytest.raises(HiyariError, match="flush interval"):
        RecorderConfig(flush_interval_s=0).validate()
    with pytest.raises(HiyariError, match="compression"):
        RecorderConfig(compression="gzip").validate()
    with Recorder(tmp_path / "r.mcap") as rec:
        with pytest.raises(HiyariError, match="ego 'nobody' is not in the world state"):
            rec.write_world(_state(0.1, 2), ego_id="nobody")
        with pytest.raises(ValueError, match="time must be finite"):
            rec.write_world(_state(-1.0, 2))
    with pytest.raises(HiyariError, match="recorder is closed"):
        rec.write_world(_state(0.2, 2))
