"""What a hiyari recording (one MCAP file per run) contains: topics, metadata and time stamps.

Layout (every time stamp is simulation time in nanoseconds, ``log_time == publish_time``):

- ``/osi/ground_truth``: ``osi3.GroundTruth`` per step (all actors, the ego as
  ``host_vehicle_id``, environmental conditions, the traffic lights with their states and,
  in the first frame after ``Recorder.write_road`` (every frame with
  ``RecorderConfig.road_every_frame``), the static road: lanes, lane boundaries, stationary
  objects; see :mod:`hiyari.bridge.record.osi_road`). Moving objects have OSI ids 1, 2, 3 ... in
  order of appearance, each with a ``source_reference`` naming the SUMO id; road entities
  have ids from 2^32.
- ``/osi/sensor_data``: every object list (each sensor's and ``fusion``) as
  ``osi3.SensorData``, told apart by ``sensor_id``; registered before the per-source channels,
  so an OSI reader that asks for SensorData without a topic gets every source, not one.
- ``/osi/sensor_data/<source>``: the same messages, one source per channel.
- ``/osi/sensor_view``: ``osi3.SensorView`` per sensor output of a sensor with a known
  mount: ``sensor_id``, mounting position in the vehicle frame, view configuration (field of
  view), host vehicle id; its ground truth is the ``/osi/ground_truth`` message of that time.
  SensorData of such a sensor carries the ego as ``host_vehicle_location`` and the sensor's
  ``mounting_position``, both mountings in OSI's vehicle frame: origin at the middle of the
  ego's rear axle, the box centre + ``bbcenter_to_rear`` of the host in the ground truth
  (format 3 and older: the ego's ground-rectangle centre, which their ``bbcenter_to_rear``
  says too). Every vehicle's ``vehicle_attributes`` (axles, wheels, ground clearance) come
  from its class and size (:mod:`hiyari.bridge.record.osi_vehicle`); docs/osi_fields.md
  lists every OSI field written.
- ``/lidar/<sensor>``: every point of every scan as ``hiyari.LidarScan`` (below); with
  ``RecorderConfig(lidar_encoding="float32")`` instead a ``foxglove.PointCloud`` of float32
  fields x y z intensity range truth_id, bit for bit (as format version 2).
- ``/lidar/<sensor>/thinned``: ``foxglove.PointCloud``, 1 in ``lidar_display_every`` points
  of each scan (channel metadata ``hiyari.thinning`` says how many), float32 fields x y z
  intensity truth_id in the sensor frame with the sensor pose, for Foxglove's 3D panel,
  which cannot decode ``hiyari.LidarScan``. Not the data: the full scan is ``/lidar/<sensor>``.
- ``/radar/<sensor>``: ``foxglove.PointCloud``.
- ``/camera/<sensor>/image``: ``foxglove.CompressedImage``; ``/camera/<sensor>/calibration``:
  ``foxglove.CameraCalibration``; ``/camera/<sensor>/pose``: ``foxglove.FrameTransform``.
- ``/markers/ground_truth``, ``/markers/objects/<source>``, ``/markers/road_mesh``:
  ``foxglove.SceneUpdate`` boxes and the road triangles, for Foxglove's 3D panel.
- ``/hiyari/actor_ids`` (JSON): OSI id -> SUMO id, written when new actors appear.
- ``/hiyari/ego_status``, ``/hiyari/collisions`` (JSON).
- Attachment ``road_mesh.npz``: the static scene mesh, exactly (vertices, faces, material).
- Metadata ``net.asam.osi.trace`` (OSI trace-file conventions), ``hiyari`` (scenario, seed,
  toolkit version, format version, user metadata), ``hiyari.sensor`` (one per sensor config,
  with its OSI ``sensor_id``) and ``hiyari.road`` (what the road holds).

A run writes ``<name>.mcap.part`` and renames it to ``<name>.mcap`` when closed.

``hiyari.LidarScan`` (protobuf, proto3; the schema is stored in the file as a FileDescriptorSet,
so any MCAP protobuf reader decodes the message; :mod:`hiyari.bridge.record.lidar_scan`
encodes and decodes it)::

    message LidarScan {
      uint64 timestamp_ns = 1;          // simulation time of the scan start, ns
      string frame_id = 2;              // "world": the frame sensor_to_frame maps into
      repeated double sensor_to_frame = 3;  // 4x4 sensor pose, row-major (16 values)
      uint32 point_count = 4;           // N
      double range_step_m = 5;          // 0.004
      double angle_step_rad = 6;        // 2 pi / 2^22
      double log2_intensity_step = 7;   // 1 / 1024
      sint32 intensity_zero_code = 8;   // -2^20: the code of intensity 0
      string codec = 9;                 // "delta-zigzag-u32-byteplanes-zstd"
      bytes data = 10;                  // one zstd frame, below
    }

Points are in the sensor frame (x forward, y left, z up, m), in the order the sensor produced
them. Each point has five integer codes, in this column order:

1. azimuth ``a = round(atan2(y, x) / angle_step_rad)``
2. elevation ``e = round(atan2(z, hypot(x, y)) / angle_step_rad)``
3. range ``r = round(range / range_step_m)`` (the distance from the sensor origin)
4. intensity ``i = round(log2(intensity) / log2_intensity_step)``, or
   ``intensity_zero_code`` for 0
5. truth id: the OSI id of the actor hit, -1 the static scene, -2 no real surface

``data`` decompresses (zstd) to ``5 x 4 x N`` bytes: for each column in that order, the
column's values ``v[k]`` are replaced by ``d[k] = v[k] - v[k-1]`` (``v[-1] = 0``), mapped to
unsigned 32-bit ``z = (d << 1) ^ (d >> 31)`` (zigzag), and written as four byte planes:
byte 0 (least significant) of every ``z``, then byte 1, byte 2, byte 3. Decoding inverts
each step: ``d = (z >> 1) ^ -(z & 1)``, ``v = cumsum(d)``; then ``range = r x
range_step_m``, azimuth ``A = a x angle_step_rad``, elevation ``E = e x angle_step_rad``,
``(x, y, z) = range x (cos E cos A, cos E sin A, sin E)``, ``intensity = 2^(i x
log2_intensity_step)``. Quantisation: range within ``range_step_m / 2`` (2 mm), position
within ``range_step_m / 2 + range x angle_step_rad`` (+ float32 rounding), intensity within a
factor ``2^(log2_intensity_step / 2)`` (0.034 %); truth ids, order, pose and time exact.
"""

from __future__ import annotations

import math

#: Bumped when the layout above changes in a way readers must know about.
FORMAT_NAME = "hiyari-recording"
FORMAT_VERSION = "4"
PART_SUFFIX = ".part"

TOPIC_GROUND_TRUTH = "/osi/ground_truth"
TOPIC_SENSOR_DATA = "/osi/sensor_data/"
TOPIC_SENSOR_DATA_ALL = "/osi/sensor_data"
TOPIC_SENSOR_VIEW = "/osi/sensor_view"
TOPIC_LIDAR = "/lidar/"
LIDAR_THINNED_SUFFIX = "/thinned"
TOPIC_RADAR = "/radar/"
TOPIC_CAMERA = "/camera/"
TOPIC_MARKERS_TRUTH = "/markers/ground_truth"
TOPIC_MARKERS_OBJECTS = "/markers/objects/"
TOPIC_MARKERS_MESH = "/markers/road_mesh"
TOPIC_ACTOR_IDS = "/hiyari/actor_ids"
TOPIC_EGO_STATUS = "/hiyari/ego_status"
TOPIC_COLLISIONS = "/hiyari/collisions"

ATTACHMENT_MESH = "road_mesh.npz"
METADATA_OSI = "net.asam.osi.trace"
METADATA_HIYARI = "hiyari"
METADATA_SENSOR = "hiyari.sensor"
METADATA_ROAD = "hiyari.road"

#: The world frame of every Foxglove message (SUMO network coordinates, metres, z up).
WORLD_FRAME = "world"


def camera_topics(sensor: str) -> tuple[str, str, str]:
    """(image, calibration, pose) topics of one camera."""
    base = f"{TOPIC_CAMERA}{sensor}"
    return f"{base}/image", f"{base}/calibration", f"{base}/pose"


def to_ns(time_s: float) -> int:
    """Simulation seconds -> integer nanoseconds (rounded, so 0.1 * k maps to k * 10^8)."""
    if not math.isfinite(time_s) or time_s < 0:
        raise ValueError(f"time must be finite and >= 0 s, got {time_s}")
    return int(round(time_s * 1e9))


def from_ns(ns: int) -> float:
    """Integer nanoseconds -> simulation seconds."""
    return ns / 1e9
