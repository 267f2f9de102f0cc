"""Recorder: one MCAP file per run, ground truth and object lists as ASAM OSI, raw LiDAR as
``hiyari.LidarScan`` (:mod:`hiyari.bridge.record.lidar_scan`), other dense data as Foxglove
schemas (layout in :mod:`hiyari.bridge.record.format`).

Crash safety: the file is written as ``<name>.mcap.part`` and renamed to ``<name>.mcap`` by
:meth:`Recorder.close`. Chunks are closed only between time steps, at least every
``flush_interval_s`` of simulation time, and pushed to the operating system at once, so a run
killed midway leaves a ``.part`` file whose complete chunks :class:`Recording` reads (up to the
last flushed step). A run that ends with an exception is closed properly but keeps the
``.part`` name, so it is never mistaken for a finished recording.
"""

from __future__ import annotations

import dataclasses
import io
import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import google.protobuf
import numpy as np
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import CompressionType, Writer
from mcap_protobuf.schema import register_schema
from osi3.osi_groundtruth_pb2 import GroundTruth
from osi3.osi_sensordata_pb2 import SensorData
from osi3.osi_sensorview_pb2 import SensorView

from hiyari.bridge.record import format as fmt
from hiyari.bridge.record import foxglove_convert as fox
from hiyari.bridge.record import lidar_scan, osi_vehicle
from hiyari.bridge.record import osi_convert as osi
from hiyari.bridge.record.osi_road import RoadEncoder
from hiyari.errors import HiyariError, WriteFailed, writing
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.net.road.geometry import RoadGeometry
from hiyari.sensors.outputs import CameraFrame, ObjectList, PointCloud, RadarDetections
from hiyari.traffic.collision import Collision
from hiyari.traffic.commands import SignalLink
from hiyari.traffic.world_state import WorldState
from hiyari.version import __version__

_COMPRESSION = {
    "zstd": CompressionType.ZSTD,
    "lz4": CompressionType.LZ4,
    "none": CompressionType.NONE,
}

_EGO_SCHEMA = {
    "title": "hiyari.EgoStatus",
    "type": "object",
    "properties": {
        "time": {"type": "number", "description": "simulation time, s"},
        "speed_mps": {"type": "number"},
        "ttc_s": {"type": ["number", "null"], "description": "null when no target"},
        "aeb_state": {"type": "string"},
        "accel_cmd_mps2": {"type": "number"},
    },
}
_COLLISION_SCHEMA = {
    "title": "hiyari.Collisions",
    "type": "object",
    "properties": {
        "time": {"type": "number"},
        "collisions": {
            "type": "array",
            "items": {
                "type": "object",
                "properties": {
                    "a": {"type": "string"},
                    "b": {"type": "string"},
                    "kind": {"type": "string"},
                    "depth_m": {"type": "number"},
                    "reported_by_sumo": {"type": "boolean"},
                },
            },
        },
    },
}
_ACTOR_ID_SCHEMA = {
    "title": "hiyari.ActorIds",
    "type": "object",
    "description": "OSI moving-object id (as text) -> SUMO id, for actors new at this time",
    "additionalProperties": {"type": "string"},
}


@dataclass(frozen=True)
class RecorderConfig:
    """How a run is written. Times in simulation seconds, sizes in bytes."""

    flush_interval_s: float = 1.0  # chunk length: a killed run loses at most this much
    max_buffer_bytes: int = 8 * 2**20  # close a chunk early when this much data is pending
    compression: str = "zstd"  # "zstd", "lz4" or "none"
    # "compact": every LiDAR point as hiyari.LidarScan (4 mm range steps, ~0.7 byte a point)
    # plus a thinned foxglove.PointCloud for display; "float32": every point as a
    # foxglove.PointCloud of float32 fields, bit for bit (~24 bytes a point before zstd)
    lidar_encoding: str = "compact"
    # 1 in this many points of each compact scan also go to /lidar/<sensor>/thinned for
    # Foxglove (0: none); 1 in 8 of a 64 x 2,048 scan costs ~75 MB per simulated minute
    lidar_display_every: int = 32
    camera_format: str = "jpeg"  # "jpeg" (lossy) or "png" (lossless)
    jpeg_quality: int = 90
    foxglove_boxes: bool = True  # also write SceneUpdate boxes for Foxglove's 3D panel
    # the OSI road (lanes, boundaries, stationary objects) in the first GroundTruth after
    # write_road, as OSI tools write static content (esmini; OSMP's GroundTruthInit); True
    # repeats it in every frame (self-contained frames; ~0.5 MB per frame on a city grid)
    road_every_frame: bool = False
    creation_time: str | None = None  # ISO 8601 UTC; None = now (fix it for identical files)

    def validate(self) -> None:
        """Raise HiyariError for impossible settings."""
        if not self.flush_interval_s > 0:
            raise HiyariError(f"flush interval must be positive, got {self.flush_interval_s} s")
        if self.max_buffer_bytes < 1024:
            raise HiyariError(f"max buffer must be >= 1024 bytes, got {self.max_buffer_bytes}")
        if self.compression not in _COMPRESSION:
            raise HiyariError(
                f"compression must be one of {', '.join(_COMPRESSION)}, got {self.compression!r}"
            )
        if self.lidar_encoding not in ("compact", "float32"):
            raise HiyariError(
                f"lidar encoding must be compact or float32, got {self.lidar_encoding!r}"
            )
        if self.lidar_display_every < 0:
            raise HiyariError(
                f"lidar display thinning must be >= 0 (0: none), got {self.lidar_display_every}"
            )
        if self.camera_format not in ("jpeg", "png"):
            raise HiyariError(f"camera format must be jpeg or png, got {self.camera_format!r}")
        if not 1 <= self.jpeg_quality <= 100:
            raise HiyariError(f"JPEG quality must be 1..100, got {self.jpeg_quality}")


@dataclass(frozen=True)
class SensorMount:
    """Where a sensor sits on the ego and what it covers, for OSI SensorView / SensorData.

    ``kind``: "lidar", "radar" or "camera"; ``sensor_to_vehicle``: (4, 4) sensor frame (x
    boresight, y left, z up) in the vehicle frame (origin at the ground-rectangle centre);
    fields of view in radians (None: not stated).
    """

    kind: str
    sensor_to_vehicle: np.ndarray
    fov_horizontal: float | None = None
    fov_vertical: float | None = None


class _PartFile:
    """The ``.part`` file the MCAP writer writes into. A write that fails for a full disk or
    a failed device raises WriteFailed naming the recording, once: the file is then left as
    it is, readable up to its last complete chunk."""

    def __init__(self, part: Path, final: Path) -> None:
        self._f = open(part, "wb")  # noqa: SIM115 - closed in close()
        self._part, self._final = part, final
        self.failed = False

    def _guard(self, op: Any, *args: Any) -> Any:
        outcome = f"{self._part} keeps the recording up to its last complete chunk"
        try:
            with writing(self._final, outcome):
                return op(*args)
        except WriteFailed:
            self.failed = True
            raise

    def write(self, data: bytes) -> int:
        return self._guard(self._f.write, data)

    def flush(self) -> None:
        self._guard(self._f.flush)

    def tell(self) -> int:
        return self._f.tell()

    def close(self) -> None:
        try:  # what is still buffered goes out if it can; a full disk was reported already
            self._f.close()
        except OSError:
            if not self.failed:
                raise


_VIEWS = {
    "lidar": "lidar_sensor_view",
    "radar": "radar_sensor_view",
    "camera": "camera_sensor_view",
}


def metadata_text(value: Any) -> str:
    """A metadata value as MCAP text: strings as they are, everything else as JSON."""
    if isinstance(value, str):
        return value
    return json.dumps(value, default=_json_default, sort_keys=True)


def _json_default(value: Any) -> Any:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return dataclasses.asdict(value)
    if isinstance(value, np.ndarray | np.generic):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, set | frozenset | tuple):
        return list(value)
    return str(value)


def _finite_or_none(value: float | None) -> float | None:
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


class Recorder:
    """Writes one run to ``path`` (must end in ``.mcap``); attach it to any run.

    ``metadata``: free key/values stored in the ``hiyari`` metadata record (give at least
    ``scenario`` and ``seed``); non-string values are stored as JSON. Every ``write_*`` takes
    the simulation time from its input. Use as a context manager or call :meth:`close`.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        metadata: Mapping[str, Any] | None = None,
        config: RecorderConfig | None = None,
    ) -> None:
        self.config = config or RecorderConfig()
        self.config.validate()
        self.path = Path(path)
        if self.path.suffix != ".mcap":
            raise HiyariError(f"{self.path}: a recording file name must end in .mcap")
        self.part_path = self.path.with_name(self.path.name + fmt.PART_SUFFIX)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file = _PartFile(self.part_path, self.path)
        self._writer = Writer(
            self._file,
            # Chunks are closed by _begin_step between time steps; the writer's own limit
            # only guards memory against a single huge step.
            chunk_size=max(4 * self.config.max_buffer_bytes, 64 * 2**20),
            compression=_COMPRESSION[self.config.compression],
        )
        self._writer.start(profile="", library=f"hiyari {__version__}")
        self._ids = osi.OsiIdMap()
        self._gt = osi.GroundTruthEncoder()
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._sensor_ids: dict[str, int] = {}
        self._mounts: dict[str, SensorMount] = {}
        self._road: RoadEncoder | None = None
        self._road_written = False
        # the ego at the last ground truth: time ns, vehicle pose (ground-rectangle centre),
        # (length, width, height), OSI id, bbcenter_to_rear
        self._host: tuple[int, np.ndarray, tuple[float, float, float], int, np.ndarray] | None
        self._host = None
        self._step_ns = -1
        self._flushed_ns = 0
        self._pending = 0
        self._has_mesh = False
        self._closed = False
        self.frames = 0
        self._write_file_metadata(dict(metadata or {}))

    # ------------------------------------------------------------------ lifecycle
    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, exc_type: object, exc: object, tb: object) -> None:
        self.close(complete=exc_type is None)

    def close(self, complete: bool = True) -> Path:
        """Finish the file; rename it to its final name when ``complete`` (safe to call twice).

        Returns the path of the file on disk (the ``.part`` name when not complete). After a
        failed write (a full disk: WriteFailed) the ``.part`` file is only closed, readable up
        to its last complete chunk.
        """
        complete = complete and not self._file.failed
        if not self._closed:
            self._closed = True
            try:
                if not self._file.failed:
                    self._writer.finish()
            finally:
                self._file.close()
            if complete:
                os.replace(self.part_path, self.path)
        return self.path if complete else self.part_path

    def flush(self) -> None:
        """Close the current chunk and hand everything written so far to the OS."""
        self._writer.flush()
        self._flushed_ns = max(self._step_ns, 0)
        self._pending = 0

    # ------------------------------------------------------------------ channels
    def _schema(self, key: str, register: Any) -> int:
        if key not in self._schemas:
            self._schemas[key] = register()
        return self._schemas[key]

    def _proto_channel(self, topic: str, message_class: Any, metadata: dict[str, str]) -> int:
        cid = self._channels.get(topic)
        if cid is None:
            name = message_class.DESCRIPTOR.full_name
            sid = self._schema(name, lambda: register_schema(self._writer, message_class))
            cid = self._writer.register_channel(topic, MessageEncoding.Protobuf, sid, metadata)
            self._channels[topic] = cid
        return cid

    def _osi_channel(self, topic: str, message_class: Any, description: str) -> int:
        return self._proto_channel(
            topic,
            message_class,
            {
                "net.asam.osi.trace.channel.osi_version": osi.OSI_VERSION,
                "net.asam.osi.trace.channel.protobuf_version": google.protobuf.__version__,
                "net.asam.osi.trace.channel.description": description,
            },
        )

    def _json_channel(self, topic: str, schema: dict) -> int:
        cid = self._channels.get(topic)
        if cid is None:
            data = json.dumps(schema).encode()
            sid = self._schema(
                schema["title"],
                lambda: self._writer.register_schema(
                    schema["title"], SchemaEncoding.JSONSchema, data
                ),
            )
            cid = self._writer.register_channel(topic, MessageEncoding.JSON, sid, {})
            self._channels[topic] = cid
        return cid

    # ------------------------------------------------------------------ low level
    def _begin_step(self, ns: int) -> None:
        """Called before every message: close the chunk when a new time step begins."""
        if self._closed:
            raise HiyariError(f"{self.path}: the recorder is closed")
        if ns > self._step_ns:
            due = ns - self._flushed_ns >= fmt.to_ns(self.config.flush_interval_s)
            if self._step_ns >= 0 and (due or self._pending >= self.config.max_buffer_bytes):
                self.flush()
            self._step_ns = ns

    def _put(self, channel: int, ns: int, data: bytes) -> None:
        self._writer.add_message(channel, log_time=ns, data=data, publish_time=ns)
        self._pending += len(data)

    def _proto(self, channel: int, ns: int, message: Any) -> None:
        self._put(channel, ns, message.SerializeToString())

    def _json(self, channel: int, ns: int, payload: dict) -> None:
        self._put(channel, ns, json.dumps(payload, separators=(",", ":")).encode())

    def _osi_ids(self, sumo_ids: Sequence[str], ns: int) -> list[int]:
        """OSI ids for SUMO ids; new ones are announced on the actor-id channel first."""
        ids = self._ids.get_many(sumo_ids)
        new = self._ids.take_new()
        if new:
            cid = self._json_channel(fmt.TOPIC_ACTOR_IDS, _ACTOR_ID_SCHEMA)
            self._json(cid, ns, {str(k): v for k, v in new.items()})
        return ids

    def _write_file_metadata(self, metadata: dict[str, Any]) -> None:
        created = self.config.creation_time or datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
        pb = google.protobuf.__version__
        scenario = metadata_text(metadata.get("scenario", ""))
        self._writer.add_metadata(
            fmt.METADATA_OSI,
            {
                "version": osi.OSI_VERSION,
                "min_osi_version": osi.OSI_VERSION,
                "max_osi_version": osi.OSI_VERSION,
                "min_protobuf_version": pb,
                "max_protobuf_version": pb,
                "creation_time": created,
                "description": f"hiyari recording{': ' + scenario if scenario else ''}",
                "authors": "hiyari",
                "data_sources": "SUMO (libsumo) traffic; hiyari sensor, recognition and "
                "fusion models",
            },
        )
        record = {k: metadata_text(v) for k, v in metadata.items()}
        record.update(
            format=fmt.FORMAT_NAME,
            format_version=fmt.FORMAT_VERSION,
            toolkit_version=__version__,
            creation_time=created,
        )
        record.setdefault("scenario", "")
        record.setdefault("seed", "")
        self._writer.add_metadata(fmt.METADATA_HIYARI, record)

    # ------------------------------------------------------------------ public writes
    def add_sensor_config(self, name: str, config: Any, mount: SensorMount | None = None) -> None:
        """Store one sensor's configuration (dataclass, mapping or text) as metadata.

        ``mount``: where it sits on the ego; then every object list of source ``name`` is
        written with its mounting position, and an ``osi3.SensorView`` (mounting position,
        view configuration, host vehicle) goes to ``/osi/sensor_view`` at the same time.
        """
        if mount is not None:
            if mount.kind not in _VIEWS:
                raise HiyariError(f"sensor {name!r}: kind must be one of {', '.join(_VIEWS)}")
            self._mounts[name] = mount
        record = {"name": name, "config": metadata_text(config)}
        record["osi_sensor_id"] = str(self._sensor_id(name))
        self._writer.add_metadata(fmt.METADATA_SENSOR, record)

    @property
    def signal_ids(self) -> list[str]:
        """Traffic light ids of the recorded road (pass their states to :meth:`write_world`)."""
        return [] if self._road is None else list(self._road.signal_ids)

    def _sensor_id(self, source: str) -> int:
        return self._sensor_ids.setdefault(source, len(self._sensor_ids) + 1)

    def write_road(
        self,
        geometry: RoadGeometry,
        mesh: SceneMesh | None = None,
        signal_links: Sequence[SignalLink] = (),
    ) -> dict[str, int]:
        """Put the road into the ground truth from now on: lanes and lane boundaries from
        ``geometry``, stationary objects (guard rails, buildings) from the static scene
        ``mesh``, traffic lights from ``signal_links`` (their states come with each
        :meth:`write_world`). Returns the counts of what was encoded."""
        if self._road is not None:
            raise HiyariError(f"{self.path}: the road is already recorded")
        self._road = RoadEncoder(geometry, mesh, signal_links)
        counts = {**self._road.counts, "traffic_lights": len(self._road.signal_ids)}
        self._writer.add_metadata(
            fmt.METADATA_ROAD,
            {"net": str(geometry.path.name), **{k: str(v) for k, v in counts.items()}},
        )
        return counts

    def write_static_mesh(self, mesh: SceneMesh, time: float = 0.0) -> None:
        """Store the static road mesh once (exact arrays as an attachment, plus markers)."""
        if self._has_mesh:
            raise HiyariError(f"{self.path}: the static mesh is already recorded")
        self._has_mesh = True
        ns = fmt.to_ns(time)
        buf = io.BytesIO()
        np.savez_compressed(buf, vertices=mesh.vertices, faces=mesh.faces, material=mesh.material)
        self._writer.add_attachment(0, ns, fmt.ATTACHMENT_MESH, "application/x-npz", buf.getvalue())
        if self.config.foxglove_boxes:
            self._begin_step(ns)
            update = fox.mesh_update(mesh, ns)
            self._proto(self._proto_channel(fmt.TOPIC_MARKERS_MESH, type(update), {}), ns, update)
        self.flush()

    def write_world(
        self,
        state: WorldState,
        ego_id: str | None = None,
        environment: Any = None,
        collisions: Sequence[Collision] = (),
        signals: Mapping[str, str] | None = None,
    ) -> None:
        """Ground truth of one step (one frame of the recording).

        ``ego_id``: the SUMO id of the ego (OSI ``host_vehicle_id``; highlighted in replay).
        ``environment``: a mapping or object with the fields in
        ``osi_convert.ENVIRONMENT_FIELDS`` (or an ``osi3.EnvironmentalConditions``).
        ``collisions``: contacts at this step (written when not empty).
        ``signals``: traffic light id -> SUMO state string (``Simulation.signal_states``),
        for the lights of :meth:`write_road`.
        """
        ns = fmt.to_ns(state.time)
        self._begin_step(ns)
        osi_ids = self._osi_ids(state.ids.tolist(), ns)
        ego_osi = None
        if ego_id is not None:
            rows = np.flatnonzero(state.ids == ego_id)
            if not len(rows):
                raise HiyariError(f"ego {ego_id!r} is not in the world state at t={state.time} s")
            ego_osi = self._ids.get(ego_id)
            r = int(rows[0])
            x, y, z = state.xyz[r].tolist()
            pose = osi.vehicle_pose(x, y, z, float(state.heading[r]))
            dims = (float(state.length[r]), float(state.width[r]), float(state.height[r]))
            rear, _ = osi_vehicle.axle_vectors(int(state.cls[r]), dims[0], dims[2])
            self._host = (ns, pose, dims, ego_osi, rear)
        gt = self._gt.encode(state, osi_ids, ns, ego_osi, environment)
        if self._road is not None:
            if self.config.road_every_frame or not self._road_written:
                gt += self._road.static
                self._road_written = True
            if signals:
                gt += self._road.traffic_lights(signals)
        cid = self._osi_channel(fmt.TOPIC_GROUND_TRUTH, GroundTruth, "ground truth, every step")
        self._put(cid, ns, gt)
        if self.config.foxglove_boxes:
            boxes = fox.truth_boxes(state, ego_id, ns)
            self._put(self._proto_channel(fmt.TOPIC_MARKERS_TRUTH, SceneUpdate, {}), ns, boxes)
        if collisions:
            self.write_collisions(state.time, collisions)
        self.frames += 1

    def write_collisions(self, time: float, collisions: Sequence[Collision]) -> None:
        """Contacts at ``time`` (s)."""
        ns = fmt.to_ns(time)
        self._begin_step(ns)
        payload = {
            "time": time,
            "collisions": [
                {
                    "a": c.a,
                    "b": c.b,
                    "kind": c.kind,
                    "depth_m": c.depth,
                    "reported_by_sumo": c.reported_by_sumo,
                }
                for c in collisions
            ],
        }
        self._json(self._json_channel(fmt.TOPIC_COLLISIONS, _COLLISION_SCHEMA), ns, payload)

    def write_point_cloud(self, pc: PointCloud) -> None:
        """One LiDAR scan on ``/lidar/<sensor>`` (``hiyari.LidarScan``, or a float32
        ``foxglove.PointCloud`` with ``lidar_encoding="float32"``), and the thinned display
        cloud on ``/lidar/<sensor>/thinned``. ``pc`` is only read."""
        ns = fmt.to_ns(pc.time)
        self._begin_step(ns)
        actor_osi = np.asarray(self._osi_ids(pc.actor_ids.tolist(), ns), np.int64)
        topic = fmt.TOPIC_LIDAR + pc.sensor
        if self.config.lidar_encoding == "float32":
            msg = fox.lidar_message(pc, actor_osi, ns)
            self._proto(self._proto_channel(topic, type(msg), {}), ns, msg)
            return
        truth = fox.truth_osi_ids(pc.hit, actor_osi)
        every = self.config.lidar_display_every
        self._put(self._lidar_channel(topic, every), ns, lidar_scan.encode_scan(pc, truth, ns))
        if every:
            msg = fox.lidar_display_message(pc, truth, ns, every)
            meta = {
                "hiyari.thinning": f"1 in {every} points of each scan, for display",
                "hiyari.full_scan_topic": topic,
            }
            cid = self._proto_channel(topic + fmt.LIDAR_THINNED_SUFFIX, type(msg), meta)
            self._proto(cid, ns, msg)

    def _lidar_channel(self, topic: str, every: int) -> int:
        meta = {"hiyari.codec": lidar_scan.CODEC}
        if every:
            meta["hiyari.display_topic"] = topic + fmt.LIDAR_THINNED_SUFFIX
        return self._proto_channel(topic, lidar_scan.LidarScan, meta)

    def write_radar(self, det: RadarDetections) -> None:
        """One radar cycle on ``/radar/<sensor>``."""
        ns = fmt.to_ns(det.time)
        self._begin_step(ns)
        actor_osi = np.asarray(self._osi_ids(det.actor_ids.tolist(), ns), np.int64)
        msg = fox.radar_message(det, actor_osi, ns)
        self._proto(self._proto_channel(fmt.TOPIC_RADAR + det.sensor, type(msg), {}), ns, msg)

    def write_camera(self, frame: CameraFrame) -> None:
        """One camera image with its calibration and pose on ``/camera/<sensor>/...``."""
        ns = fmt.to_ns(frame.time)
        self._begin_step(ns)
        msgs = fox.camera_messages(frame, ns, self.config.camera_format, self.config.jpeg_quality)
        for topic, msg in zip(fmt.camera_topics(frame.sensor), msgs, strict=True):
            self._proto(self._proto_channel(topic, type(msg), {}), ns, msg)

    def write_objects(self, objects: ObjectList) -> None:
        """One object list (a sensor's or the fusion's) on ``/osi/sensor_data/<source>``."""
        ns = fmt.to_ns(objects.time)
        self._begin_step(ns)
        sensor_id = self._sensor_id(objects.source)
        truth = objects.truth.tolist()
        known = [t for t in truth if t]
        osi_of = dict(zip(known, self._osi_ids(known, ns), strict=True))
        host = None
        if self._host is not None and self._host[0] == ns:
            host = (self._host[1], self._host[2], self._host[4])
        sd = osi.sensor_data_message(
            objects, sensor_id, [osi_of.get(t) for t in truth], ns, host
        ).SerializeToString()
        # every source on one channel first: what an OSI reader gets when it asks for
        # SensorData without naming a topic (it takes the first SensorData channel)
        every = self._osi_channel(
            fmt.TOPIC_SENSOR_DATA_ALL, SensorData, "object lists of every source (by sensor_id)"
        )
        self._put(every, ns, sd)
        topic = fmt.TOPIC_SENSOR_DATA + objects.source
        cid = self._osi_channel(topic, SensorData, f"object list from {objects.source}")
        self._put(cid, ns, sd)
        mount = self._mounts.get(objects.source)
        if mount is not None and self._host is not None and self._host[0] == ns:
            view = self._sensor_view(sensor_id, mount, ns)
            cid = self._osi_channel(fmt.TOPIC_SENSOR_VIEW, SensorView, "sensor views (mounting)")
            self._proto(cid, ns, view)
        if self.config.foxglove_boxes:
            t = np.asarray(objects.frame_to_world, np.float64)
            world = objects.position @ t[:3, :3].T + t[:3, 3]
            yaw = math.atan2(t[1, 0], t[0, 0])
            boxes = fox.object_boxes(world, yaw, objects.size, objects.source, ns)
            topic = fmt.TOPIC_MARKERS_OBJECTS + objects.source
            self._put(self._proto_channel(topic, SceneUpdate, {}), ns, boxes)

    def _sensor_view(self, sensor_id: int, mount: SensorMount, ns: int) -> SensorView:
        """SensorView of one sensor: mounting position and view configuration; its ground
        truth is the /osi/ground_truth message of the same time (not repeated here)."""
        sv = SensorView()
        sv.version.CopyFrom(osi.interface_version())
        osi.set_timestamp(sv.timestamp, ns)
        sv.sensor_id.value = sensor_id
        # OSI's vehicle frame has its origin at the rear-axle middle, hiyari's mounts are
        # given from the centre of the ground rectangle (write_objects calls this with the
        # host of this time)
        to_osi = np.eye(4)
        if self._host is not None:
            sv.host_vehicle_id.value = self._host[3]
            to_osi[:3, 3] = -(self._host[4] + [0.0, 0.0, 0.5 * self._host[2][2]])
        osi.set_pose(to_osi @ np.asarray(mount.sensor_to_vehicle, np.float64), sv.mounting_position)
        view = getattr(sv, _VIEWS[mount.kind]).add().view_configuration
        view.sensor_id.value = sensor_id
        view.mounting_position.CopyFrom(sv.mounting_position)
        if mount.fov_horizontal is not None:
            view.field_of_view_horizontal = mount.fov_horizontal
        if mount.fov_vertical is not None:
            view.field_of_view_vertical = mount.fov_vertical
        return sv

    def write_ego_status(
        self,
        time: float,
        speed: float,
        ttc: float | None,
        aeb_state: str,
        accel_cmd: float,
    ) -> None:
        """Ego stack status: speed (m/s), TTC (s; None or inf when no target), AEB state
        (e.g. "off", "warning", "partial", "full"), commanded acceleration (m/s^2)."""
        ns = fmt.to_ns(time)
        self._begin_step(ns)
        payload = {
            "time": time,
            "speed_mps": float(speed),
            "ttc_s": _finite_or_none(ttc),
            "aeb_state": str(aeb_state),
            "accel_cmd_mps2": float(accel_cmd),
        }
        self._json(self._json_channel(fmt.TOPIC_EGO_STATUS, _EGO_SCHEMA), ns, payload)
