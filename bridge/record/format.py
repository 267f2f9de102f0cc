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
  ``mounting_position``; the vehicle frame's origin is the ego's ground-rectangle centre
  (``bbcenter_to_rear`` of the host in the ground truth says so).
- ``/lidar/<sensor>``, ``/radar/<sensor>``: ``foxglove.PointCloud``.
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
"""

from __future__ import annotations

import math

#: Bumped when the layout above changes in a way readers must know about.
FORMAT_NAME = "hiyari-recording"
FORMAT_VERSION = "2"
PART_SUFFIX = ".part"

TOPIC_GROUND_TRUTH = "/osi/ground_truth"
TOPIC_SENSOR_DATA = "/osi/sensor_data/"
TOPIC_SENSOR_DATA_ALL = "/osi/sensor_data"
TOPIC_SENSOR_VIEW = "/osi/sensor_view"
TOPIC_LIDAR = "/lidar/"
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
