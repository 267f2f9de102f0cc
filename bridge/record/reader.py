"""Read a hiyari recording back: frames, ground truth, sensor outputs, object lists, mesh.

:meth:`Recording.open` scans the file once, record by record, and keeps an index (topic, time,
chunk) of every message; messages are decoded when asked for (a few chunks are cached). The
scan stops at the first incomplete record, so a run killed midway (a ``.part`` file) or a
truncated copy opens up to its last complete chunk; :attr:`Recording.problem` then says what
is missing. A file that is not MCAP, or an MCAP written by another program, raises HiyariError
with one line.
"""

from __future__ import annotations

import io
import json
import struct
import threading
from collections import OrderedDict
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from foxglove_schemas_protobuf.CameraCalibration_pb2 import CameraCalibration
from foxglove_schemas_protobuf.CompressedImage_pb2 import CompressedImage
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.PointCloud_pb2 import PointCloud as FoxPointCloud
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Attachment, Channel, Chunk, Message, Metadata, Schema
from mcap.stream_reader import breakup_chunk
from osi3.osi_groundtruth_pb2 import GroundTruth
from osi3.osi_sensordata_pb2 import SensorData

from hiyari.bridge.record import format as fmt
from hiyari.bridge.record import foxglove_convert as fox
from hiyari.bridge.record import lidar_scan
from hiyari.bridge.record import osi_convert as osi
from hiyari.errors import HiyariError
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.outputs import CameraFrame, ObjectList, PointCloud, RadarDetections
from hiyari.traffic.world_state import WorldState

MCAP_MAGIC = b"\x89MCAP0\r\n"
_HEAD = struct.Struct("<BQ")
_JSON_TOPICS = (fmt.TOPIC_ACTOR_IDS, fmt.TOPIC_EGO_STATUS, fmt.TOPIC_COLLISIONS)


@dataclass
class _TopicIndex:
    """Where one topic's messages are: time (ns), chunk number, slot in the chunk.

    hiyari writes every message into a chunk; messages outside chunks are not indexed.
    """

    ns: list[int] = field(default_factory=list)
    chunk: list[int] = field(default_factory=list)
    slot: list[int] = field(default_factory=list)

    def freeze(self) -> None:
        order = np.argsort(np.asarray(self.ns, np.int64), kind="stable")
        self.ns = np.asarray(self.ns, np.int64)[order]
        self.chunk = np.asarray(self.chunk, np.int64)[order]
        self.slot = np.asarray(self.slot, np.int64)[order]


class _Scan:
    """One pass over the file's records (stops at the first incomplete one)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.size = path.stat().st_size
        self.channels: dict[int, Channel] = {}
        self.schemas: dict[int, Schema] = {}
        self.metadata: list[tuple[str, dict[str, str]]] = []
        self.attachments: dict[str, Attachment] = {}
        self.chunk_offsets: list[int] = []
        self.index: dict[str, _TopicIndex] = {}
        self.json: dict[str, list[tuple[int, Any]]] = {t: [] for t in _JSON_TOPICS}
        self.data_end = False
        self.ends_with_magic = False
        self.stopped_at: int | None = None  # byte offset of the first unreadable record
        self.stop_reason = ""
        try:
            with path.open("rb") as f:
                if f.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
                    raise HiyariError(
                        f"{path}: not an MCAP file (it does not start with MCAP magic)"
                    )
                self._records(f)
                f.seek(max(self.size - len(MCAP_MAGIC), 0))
                self.ends_with_magic = f.read() == MCAP_MAGIC
        except OSError as exc:
            raise HiyariError(f"{path}: cannot read the file ({exc.strerror or exc})") from None

    def _records(self, f: io.BufferedReader) -> None:
        pos = len(MCAP_MAGIC)
        while True:
            head = f.read(_HEAD.size)
            if len(head) < _HEAD.size:
                self._stop(pos, "the file ends inside a record header")
                return
            opcode, length = _HEAD.unpack(head)
            end = pos + _HEAD.size + length
            if end > self.size:
                self._stop(pos, f"a record of {length} bytes runs past the end of the file")
                return
            if opcode == Opcode.DATA_END:
                self.data_end = True
                return
            if opcode in (
                Opcode.CHUNK,
                Opcode.SCHEMA,
                Opcode.CHANNEL,
                Opcode.METADATA,
                Opcode.ATTACHMENT,
            ):
                body = f.read(length)
                try:
                    self._record(opcode, body, pos)
                except Exception as exc:  # noqa: BLE001 - any decode failure ends the scan
                    self._stop(pos, f"a corrupt record ({type(exc).__name__}: {exc})")
                    return
            else:
                f.seek(length, io.SEEK_CUR)
            pos = end

    def _stop(self, pos: int, reason: str) -> None:
        self.stopped_at = pos
        self.stop_reason = reason

    def _record(self, opcode: int, body: bytes, pos: int) -> None:
        stream = ReadDataStream(io.BytesIO(body))
        if opcode == Opcode.CHUNK:
            records = breakup_chunk(Chunk.read(stream), validate_crc=True)
            chunk_no = len(self.chunk_offsets)
            self.chunk_offsets.append(pos)
            for slot, rec in enumerate(records):
                self._item(rec, chunk_no, slot)
        elif opcode == Opcode.SCHEMA:
            self._item(Schema.read(stream), -1, -1)
        elif opcode == Opcode.CHANNEL:
            self._item(Channel.read(stream), -1, -1)
        elif opcode == Opcode.METADATA:
            m = Metadata.read(stream)
            self.metadata.append((m.name, dict(m.metadata)))
        elif opcode == Opcode.ATTACHMENT:
            a = Attachment.read(stream)
            self.attachments[a.name] = a

    def _item(self, rec: Any, chunk_no: int, slot: int) -> None:
        if isinstance(rec, Schema):
            self.schemas[rec.id] = rec
        elif isinstance(rec, Channel):
            self.channels[rec.id] = rec
        elif isinstance(rec, Message):
            channel = self.channels.get(rec.channel_id)
            if channel is None:
                raise ValueError(f"message on unknown channel {rec.channel_id}")
            if channel.topic in self.json:
                self.json[channel.topic].append((rec.log_time, json.loads(rec.data)))
            idx = self.index.setdefault(channel.topic, _TopicIndex())
            idx.ns.append(rec.log_time)
            idx.chunk.append(chunk_no)
            idx.slot.append(slot)


class Recording:
    """A hiyari recording opened for reading; frames are the ground-truth steps.

    Attributes: ``path``; ``complete`` (False for a ``.part`` or truncated file); ``problem``
    (one line on what is missing, or None); ``metadata`` (the ``hiyari`` record);
    ``osi_metadata`` (``net.asam.osi.trace``); ``sensor_configs`` (name -> JSON text);
    ``times`` (frame times, s); ``lidar_sensors``, ``radar_sensors``, ``camera_sensors``,
    ``object_sources``; ``id_names`` (OSI id -> SUMO id).
    """

    def __init__(self, path: str | Path, cache_chunks: int = 8) -> None:
        self.path = Path(path)
        if not self.path.is_file():
            part = self.path.with_name(self.path.name + fmt.PART_SUFFIX)
            hint = (
                f" ({part.name} is an unfinished recording: open it by name)"
                if part.is_file()
                else ""
            )
            raise HiyariError(f"{self.path}: no such recording{hint}")
        scan = _Scan(self.path)
        meta = dict(scan.metadata)
        self.metadata = meta.get(fmt.METADATA_HIYARI, {})
        ended = (
            f" (it ends after {scan.stopped_at} bytes: {scan.stop_reason})"
            if scan.stopped_at
            else ""
        )
        if self.metadata.get("format") != fmt.FORMAT_NAME:
            if scan.stopped_at is not None and not scan.channels:
                raise HiyariError(f"{self.path}: the recording holds no complete frame{ended}")
            topics = sorted({c.topic for c in scan.channels.values()})
            shown = ", ".join(topics[:5]) + (" ..." if len(topics) > 5 else "") or "none"
            raise HiyariError(
                f"{self.path}: an MCAP file, but not a hiyari recording (no 'hiyari' metadata "
                f"record; topics: {shown})"
            )
        self.osi_metadata = meta.get(fmt.METADATA_OSI, {})
        self.sensor_configs = {
            m["name"]: m.get("config", "") for n, m in scan.metadata if n == fmt.METADATA_SENSOR
        }
        for idx in scan.index.values():
            idx.freeze()
        self._scan = scan
        self._index = scan.index
        gt = self._index.get(fmt.TOPIC_GROUND_TRUTH)
        if gt is None or len(gt.ns) == 0:
            raise HiyariError(f"{self.path}: the recording holds no complete frame{ended}")
        self.frame_ns: np.ndarray = gt.ns
        self.times: np.ndarray = gt.ns / 1e9
        self.id_names: dict[int, str] = {}
        for _, ids in scan.json[fmt.TOPIC_ACTOR_IDS]:
            self.id_names.update({int(k): v for k, v in ids.items()})
        self._ego = sorted(scan.json[fmt.TOPIC_EGO_STATUS], key=lambda e: e[0])
        self._ego_ns = np.array([ns for ns, _ in self._ego], np.int64)
        self._collisions = sorted(scan.json[fmt.TOPIC_COLLISIONS], key=lambda e: e[0])
        self.complete = scan.data_end and scan.ends_with_magic and self.path.suffix == ".mcap"
        self.problem: str | None = None
        if scan.data_end and not scan.ends_with_magic:
            self.problem = f"{self.path.name} lost its summary section (all data is there)"
        elif not scan.data_end:
            self.problem = (
                f"{self.path.name} is incomplete ({scan.stop_reason} at byte {scan.stopped_at}): "
                f"the run did not finish or the file was cut; reading {len(self.times)} frames "
                f"up to t={self.times[-1]:.2f} s"
            )
        elif self.path.name.endswith(fmt.PART_SUFFIX):
            self.problem = f"{self.path.name} is an unfinished recording (the run stopped early)"
        topics = self._index.keys()
        self._schema_of = {
            c.topic: scan.schemas[c.schema_id].name if c.schema_id in scan.schemas else ""
            for c in scan.channels.values()
        }
        self.lidar_sensors = [
            s for s in _names(topics, fmt.TOPIC_LIDAR) if not s.endswith(fmt.LIDAR_THINNED_SUFFIX)
        ]
        self.radar_sensors = _names(topics, fmt.TOPIC_RADAR)
        self.camera_sensors = sorted(
            {
                t[len(fmt.TOPIC_CAMERA) :].rsplit("/", 1)[0]
                for t in topics
                if t.endswith("/image") and t.startswith(fmt.TOPIC_CAMERA)
            }
        )
        self.object_sources = _names(topics, fmt.TOPIC_SENSOR_DATA)
        self._lock = threading.Lock()
        self._cache: OrderedDict[int, list[Any]] = OrderedDict()
        self._cache_size = cache_chunks
        self._gt_cache: OrderedDict[int, GroundTruth] = OrderedDict()

    @classmethod
    def open(cls, path: str | Path) -> Recording:
        """Open and index a recording (see the class docstring for bad input)."""
        return cls(path)

    def __len__(self) -> int:
        return len(self.frame_ns)

    # ------------------------------------------------------------------ raw access
    @property
    def topics(self) -> list[str]:
        """Every topic with at least one message."""
        return sorted(self._index)

    def message_times(self, topic: str) -> np.ndarray:
        """Log times (s) of a topic's messages, sorted."""
        idx = self._index.get(topic)
        return np.zeros(0) if idx is None else idx.ns / 1e9

    def _chunk(self, chunk_no: int) -> list[Any]:
        with self._lock:
            records = self._cache.get(chunk_no)
            if records is not None:
                self._cache.move_to_end(chunk_no)
                return records
            with self.path.open("rb") as f:
                f.seek(self._scan.chunk_offsets[chunk_no])
                _, length = _HEAD.unpack(f.read(_HEAD.size))
                stream = ReadDataStream(io.BytesIO(f.read(length)))
                records = breakup_chunk(Chunk.read(stream))
            self._cache[chunk_no] = records
            if len(self._cache) > self._cache_size:
                self._cache.popitem(last=False)
            return records

    def records(self) -> Iterator[Any]:
        """Every schema, channel, message, metadata and attachment record read, in file order
        within each kind: schemas and channels first, then messages chunk by chunk."""
        scan = self._scan
        yield from scan.schemas.values()
        yield from scan.channels.values()
        yield from (Metadata(name=n, metadata=m) for n, m in scan.metadata)
        yield from scan.attachments.values()
        for chunk_no in range(len(scan.chunk_offsets)):
            yield from (r for r in self._chunk(chunk_no) if isinstance(r, Message))

    def raw(self, topic: str, i: int) -> bytes:
        """Payload of the ``i``-th message (in time order) of ``topic``."""
        idx = self._index[topic]
        return self._chunk(int(idx.chunk[i]))[int(idx.slot[i])].data

    def latest(self, topic: str, time_ns: int, max_age_ns: int | None = None) -> int | None:
        """Index of the last message of ``topic`` at or before ``time_ns`` (None if none, or
        older than ``max_age_ns``)."""
        idx = self._index.get(topic)
        if idx is None:
            return None
        i = int(np.searchsorted(idx.ns, time_ns, side="right")) - 1
        if i < 0 or (max_age_ns is not None and time_ns - idx.ns[i] > max_age_ns):
            return None
        return i

    def frame_at(self, time: float) -> int:
        """Index of the last frame at or before ``time`` (s); 0 before the first."""
        return max(int(np.searchsorted(self.times, time + 1e-9, side="right")) - 1, 0)

    # ------------------------------------------------------------------ ground truth
    def ground_truth(self, k: int) -> GroundTruth:
        """The ``osi3.GroundTruth`` of frame ``k``."""
        k = range(len(self))[k]
        with self._lock:
            gt = self._gt_cache.get(k)
        if gt is None:
            gt = GroundTruth.FromString(self.raw(fmt.TOPIC_GROUND_TRUTH, k))
            with self._lock:
                self._gt_cache[k] = gt
                if len(self._gt_cache) > 64:
                    self._gt_cache.popitem(last=False)
        return gt

    def road(self) -> GroundTruth | None:
        """The recorded road: the first ground-truth frame that has lanes (its lanes, lane
        boundaries and stationary objects), or None when the run recorded no road."""
        for k in range(len(self)):
            gt = self.ground_truth(k)
            if len(gt.lane):
                return gt
            if k >= 1:  # the road goes into the first frame written after it
                return None
        return None

    def world(self, k: int) -> WorldState:
        """WorldState of frame ``k``."""
        return osi.world_state_from_ground_truth(self.ground_truth(k), self.id_names)[0]

    def world_and_ego(self, k: int) -> tuple[WorldState, str | None]:
        """(WorldState, ego SUMO id or None) of frame ``k``."""
        return osi.world_state_from_ground_truth(self.ground_truth(k), self.id_names)

    def environment(self, k: int) -> dict[str, str]:
        """Environmental conditions of frame ``k`` as readable categories."""
        return osi.environment_summary(self.ground_truth(k).environmental_conditions)

    # ------------------------------------------------------------------ sensors
    def _at(self, topic: str, k: int, max_age: float | None) -> int | None:
        age = None if max_age is None else fmt.to_ns(max_age)
        return self.latest(topic, int(self.frame_ns[k]), age)

    def point_cloud(self, sensor: str, k: int, max_age: float | None = None) -> PointCloud | None:
        """Latest LiDAR scan of ``sensor`` at frame ``k`` (None if none within ``max_age`` s)."""
        topic = fmt.TOPIC_LIDAR + sensor
        i = self._at(topic, k, max_age)
        return None if i is None else self.point_cloud_at(sensor, i)

    def point_cloud_at(self, sensor: str, i: int) -> PointCloud:
        """The ``i``-th LiDAR scan of ``sensor``: every point, from ``hiyari.LidarScan``
        (within its stated quantisation) or a float32 ``foxglove.PointCloud`` (exact)."""
        topic = fmt.TOPIC_LIDAR + sensor
        data = self.raw(topic, i)
        if self._schema_of.get(topic) == lidar_scan.SCHEMA_NAME:
            return lidar_scan.decode_scan(
                lidar_scan.LidarScan.FromString(data), sensor, self.id_names
            )
        return fox.point_cloud_from_message(FoxPointCloud.FromString(data), sensor, self.id_names)

    def radar(self, sensor: str, k: int, max_age: float | None = None) -> RadarDetections | None:
        """Latest radar cycle of ``sensor`` at frame ``k``."""
        i = self._at(fmt.TOPIC_RADAR + sensor, k, max_age)
        return None if i is None else self.radar_at(sensor, i)

    def radar_at(self, sensor: str, i: int) -> RadarDetections:
        """The ``i``-th radar cycle of ``sensor``."""
        msg = FoxPointCloud.FromString(self.raw(fmt.TOPIC_RADAR + sensor, i))
        return fox.radar_from_message(msg, sensor, self.id_names)

    def camera(self, sensor: str, k: int, max_age: float | None = None) -> CameraFrame | None:
        """Latest camera frame of ``sensor`` at frame ``k``."""
        image_t, _, _ = fmt.camera_topics(sensor)
        i = self._at(image_t, k, max_age)
        return None if i is None else self.camera_at(sensor, i)

    def camera_at(self, sensor: str, i: int) -> CameraFrame:
        """The ``i``-th camera frame of ``sensor`` (with the calibration and pose of its time)."""
        image_t, calib_t, pose_t = fmt.camera_topics(sensor)
        image = CompressedImage.FromString(self.raw(image_t, i))
        ns = image.timestamp.ToNanoseconds()
        ci, pi = self.latest(calib_t, ns), self.latest(pose_t, ns)
        calib = None if ci is None else CameraCalibration.FromString(self.raw(calib_t, ci))
        pose = None if pi is None else FrameTransform.FromString(self.raw(pose_t, pi))
        return fox.camera_from_messages(image, calib, pose, sensor)

    def objects(self, source: str, k: int, max_age: float | None = None) -> ObjectList | None:
        """Latest object list of ``source`` at frame ``k``."""
        i = self._at(fmt.TOPIC_SENSOR_DATA + source, k, max_age)
        return None if i is None else self.objects_at(source, i)

    def objects_at(self, source: str, i: int) -> ObjectList:
        """The ``i``-th object list of ``source``."""
        sd = SensorData.FromString(self.raw(fmt.TOPIC_SENSOR_DATA + source, i))
        rear = self._host_rear(osi.timestamp_ns(sd.timestamp))
        return osi.object_list_from_sensor_data(sd, source, self.id_names, rear)

    def _host_rear(self, ns: int) -> tuple[float, float, float] | None:
        """The host's ``bbcenter_to_rear`` in the ground truth at time ``ns`` (None: no host
        there, or none written, as before format 4)."""
        k = self.latest(fmt.TOPIC_GROUND_TRUTH, ns)
        if k is None:
            return None
        gt = self.ground_truth(k)
        if not gt.HasField("host_vehicle_id"):
            return None
        for m in gt.moving_object:
            if m.id.value == gt.host_vehicle_id.value:
                v = m.vehicle_attributes.bbcenter_to_rear
                return (
                    (v.x, v.y, v.z) if m.vehicle_attributes.HasField("bbcenter_to_rear") else None
                )
        return None

    # ------------------------------------------------------------------ status, mesh
    def ego_status(self, k: int, max_age: float | None = None) -> dict[str, Any] | None:
        """Latest ego status at frame ``k`` (time, speed_mps, ttc_s, aeb_state,
        accel_cmd_mps2)."""
        t = int(self.frame_ns[k])
        i = int(np.searchsorted(self._ego_ns, t, side="right")) - 1
        if i < 0 or (max_age is not None and t - self._ego_ns[i] > fmt.to_ns(max_age)):
            return None
        return self._ego[i][1]

    def collisions_until(self, k: int) -> list[dict[str, Any]]:
        """Every contact recorded up to frame ``k``, each pair once (first contact), with time."""
        t = int(self.frame_ns[k])
        first: dict[tuple[str, str], dict[str, Any]] = {}
        for ns, payload in self._collisions:
            if ns > t:
                break
            for c in payload["collisions"]:
                first.setdefault((c["a"], c["b"]), {"time": payload["time"], **c})
        return list(first.values())

    def mesh(self) -> SceneMesh | None:
        """The static road mesh, or None when the run recorded none."""
        attachment = self._scan.attachments.get(fmt.ATTACHMENT_MESH)
        if attachment is None:
            return None
        with np.load(io.BytesIO(attachment.data)) as z:
            return SceneMesh(z["vertices"], z["faces"], z["material"])


def _names(topics: Any, prefix: str) -> list[str]:
    return sorted(t[len(prefix) :] for t in topics if t.startswith(prefix))
