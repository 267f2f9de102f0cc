"""Sensor outputs, boxes and the road mesh to Foxglove schemas, and back.

LiDAR and radar become ``foxglove.PointCloud`` with the points in the sensor frame and the
sensor pose in ``pose`` (frame ``world``), so the points round-trip bit for bit; a
``truth_id`` field holds the OSI id of the actor hit, -1 for the static scene and -2 for a
return with no surface. The camera becomes ``foxglove.CompressedImage`` +
``foxglove.CameraCalibration`` + a ``foxglove.FrameTransform`` world -> ``<sensor>/optical``
(Foxglove's optical convention: x right, y down, z forward). Boxes and the road mesh become
``foxglove.SceneUpdate`` entities.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from foxglove_schemas_protobuf.CameraCalibration_pb2 import CameraCalibration
from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.CompressedImage_pb2 import CompressedImage
from foxglove_schemas_protobuf.CubePrimitive_pb2 import CubePrimitive
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.PackedElementField_pb2 import PackedElementField
from foxglove_schemas_protobuf.Point3_pb2 import Point3
from foxglove_schemas_protobuf.PointCloud_pb2 import PointCloud as FoxPointCloud
from foxglove_schemas_protobuf.Pose_pb2 import Pose
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate

from hiyari.bridge.record.format import WORLD_FRAME
from hiyari.bridge.record.style import EGO_COLOR, class_colors, material_color, source_color
from hiyari.bridge.record.wire import FixedLayout, key, varint
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.sensors.outputs import CameraFrame, PointCloud, RadarDetections
from hiyari.traffic.world_state import WorldState

_T = PackedElementField.NumericType
_NUMPY_OF = {
    _T.UINT8: "u1",
    _T.INT8: "i1",
    _T.UINT16: "<u2",
    _T.INT16: "<i2",
    _T.UINT32: "<u4",
    _T.INT32: "<i4",
    _T.FLOAT32: "<f4",
    _T.FLOAT64: "<f8",
}
_TYPE_OF = {np.dtype(v): k for k, v in _NUMPY_OF.items()}

LIDAR_DTYPE = np.dtype(
    [
        ("x", "<f4"),
        ("y", "<f4"),
        ("z", "<f4"),
        ("intensity", "<f4"),
        ("range", "<f4"),
        ("truth_id", "<i4"),
    ]
)
# the thinned display cloud next to a compact scan: what Foxglove's 3D panel colours by
LIDAR_DISPLAY_DTYPE = np.dtype(
    [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4"), ("truth_id", "<i4")]
)
RADAR_DTYPE = np.dtype(
    [
        ("x", "<f4"),
        ("y", "<f4"),
        ("z", "<f4"),
        ("range", "<f8"),
        ("range_rate", "<f8"),
        ("azimuth", "<f8"),
        ("elevation", "<f8"),
        ("snr_db", "<f8"),
        ("power_dbm", "<f8"),
        ("truth_id", "<i4"),
    ]
)

# Columns of the optical frame (x right, y down, z forward) in the body frame (x fwd, y left).
_BODY_FROM_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


# ------------------------------------------------------------------ rotations
def quat_from_matrix(r: np.ndarray) -> tuple[float, float, float, float]:
    """(w, x, y, z) unit quaternion of a 3x3 rotation matrix."""
    r = np.asarray(r, np.float64)
    tr = r[0, 0] + r[1, 1] + r[2, 2]
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = (0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s)
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        q = ((r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s)
    elif r[1, 1] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        q = ((r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        q = ((r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s)
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)  # type: ignore[return-value]


def matrix_from_quat(w: float, x: float, y: float, z: float) -> np.ndarray:
    """3x3 rotation matrix of a (w, x, y, z) quaternion."""
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def yaw_quats(yaw: np.ndarray) -> np.ndarray:
    """(N, 4) (w, x, y, z) quaternions of rotations by ``yaw`` (rad) about +z."""
    half = 0.5 * np.asarray(yaw, np.float64)
    q = np.zeros((len(half), 4))
    q[:, 0], q[:, 3] = np.cos(half), np.sin(half)
    return q


def _pose(msg: Pose, transform: np.ndarray) -> None:
    t = np.asarray(transform, np.float64)
    msg.position.x, msg.position.y, msg.position.z = t[:3, 3].tolist()
    o = msg.orientation
    o.w, o.x, o.y, o.z = quat_from_matrix(t[:3, :3])


def _transform(msg: Pose) -> np.ndarray:
    t = np.eye(4)
    o = msg.orientation
    t[:3, :3] = matrix_from_quat(o.w, o.x, o.y, o.z)
    t[:3, 3] = (msg.position.x, msg.position.y, msg.position.z)
    return t


# ------------------------------------------------------------------ point clouds
def truth_osi_ids(hit: np.ndarray, actor_osi_ids: np.ndarray) -> np.ndarray:
    """(N,) int32: OSI id of the actor each return hit, else HIT_STATIC / HIT_NONE."""
    hit = np.asarray(hit, np.int64)
    out = np.where(hit < 0, hit, 0).astype(np.int32)
    on_actor = hit >= 0
    out[on_actor] = np.asarray(actor_osi_ids, np.int64)[hit[on_actor]]
    return out


def _packed(
    dtype: np.dtype, columns: dict[str, np.ndarray], pose: np.ndarray, time_ns: int
) -> FoxPointCloud:
    n = len(next(iter(columns.values())))
    arr = np.empty(n, dtype)
    for name, values in columns.items():
        arr[name] = values
    msg = FoxPointCloud(frame_id=WORLD_FRAME, point_stride=dtype.itemsize, data=arr.tobytes())
    msg.timestamp.FromNanoseconds(time_ns)
    _pose(msg.pose, pose)
    for name in dtype.names:
        offset = dtype.fields[name][1]
        msg.fields.add(name=name, offset=offset, type=_TYPE_OF[dtype.fields[name][0]])
    return msg


def unpack_point_cloud(msg: FoxPointCloud) -> tuple[np.ndarray, np.ndarray]:
    """(structured array of the points, 4x4 pose) from any ``foxglove.PointCloud``."""
    dtype = np.dtype(
        {
            "names": [f.name for f in msg.fields],
            "formats": [_NUMPY_OF[f.type] for f in msg.fields],
            "offsets": [f.offset for f in msg.fields],
            "itemsize": msg.point_stride,
        }
    )
    n = len(msg.data) // msg.point_stride if msg.point_stride else 0
    return np.frombuffer(msg.data, dtype, count=n), _transform(msg.pose)


def lidar_message(pc: PointCloud, actor_osi_ids: np.ndarray, time_ns: int) -> FoxPointCloud:
    """LiDAR scan as ``foxglove.PointCloud`` (x y z intensity range truth_id)."""
    xyz = np.asarray(pc.xyz, np.float32).reshape(-1, 3)
    return _packed(
        LIDAR_DTYPE,
        {
            "x": xyz[:, 0],
            "y": xyz[:, 1],
            "z": xyz[:, 2],
            "intensity": pc.intensity,
            "range": pc.range,
            "truth_id": truth_osi_ids(pc.hit, actor_osi_ids),
        },
        pc.sensor_to_world,
        time_ns,
    )


def lidar_display_message(
    pc: PointCloud, truth_id: np.ndarray, time_ns: int, every: int
) -> FoxPointCloud:
    """Every ``every``-th point of a scan as ``foxglove.PointCloud`` (x y z intensity
    truth_id, float32 as measured), for display where the full scan is stored compactly;
    ``truth_id`` (N,) is the OSI id hit per point of the whole scan."""
    xyz = np.asarray(pc.xyz, np.float32).reshape(-1, 3)[::every]
    return _packed(
        LIDAR_DISPLAY_DTYPE,
        {
            "x": xyz[:, 0],
            "y": xyz[:, 1],
            "z": xyz[:, 2],
            "intensity": np.asarray(pc.intensity)[::every],
            "truth_id": np.asarray(truth_id)[::every],
        },
        pc.sensor_to_world,
        time_ns,
    )


def radar_message(det: RadarDetections, actor_osi_ids: np.ndarray, time_ns: int) -> FoxPointCloud:
    """Radar cycle as ``foxglove.PointCloud``: positions for display plus every measurement."""
    xyz = det.xyz().astype(np.float32).reshape(-1, 3)
    return _packed(
        RADAR_DTYPE,
        {
            "x": xyz[:, 0],
            "y": xyz[:, 1],
            "z": xyz[:, 2],
            "range": det.range,
            "range_rate": det.range_rate,
            "azimuth": det.azimuth,
            "elevation": det.elevation,
            "snr_db": det.snr_db,
            "power_dbm": det.power_dbm,
            "truth_id": truth_osi_ids(det.hit, actor_osi_ids),
        },
        det.sensor_to_world,
        time_ns,
    )


def actor_hits(truth_id: np.ndarray, id_names: dict[int, str]) -> tuple[np.ndarray, np.ndarray]:
    """(hit rows, actor ids) rebuilt from truth ids: actors are the distinct ids hit."""
    truth_id = np.asarray(truth_id, np.int64)
    actors = np.unique(truth_id[truth_id > 0])
    hit = np.where(truth_id <= 0, truth_id, 0).astype(np.int32)
    on_actor = truth_id > 0
    hit[on_actor] = np.searchsorted(actors, truth_id[on_actor])
    names = np.array([id_names.get(int(a), str(int(a))) for a in actors], dtype=object)
    return hit, names


def point_cloud_from_message(
    msg: FoxPointCloud, sensor: str, id_names: dict[int, str]
) -> PointCloud:
    """PointCloud from a hiyari LiDAR message (``actor_ids`` = the actors hit)."""
    pts, pose = unpack_point_cloud(msg)
    hit, actors = actor_hits(pts["truth_id"], id_names)
    return PointCloud(
        time=msg.timestamp.ToNanoseconds() / 1e9,
        sensor=sensor,
        sensor_to_world=pose,
        xyz=np.stack([pts["x"], pts["y"], pts["z"]], 1).astype(np.float32),
        intensity=pts["intensity"].astype(np.float32),
        range=pts["range"].astype(np.float32),
        hit=hit,
        actor_ids=actors,
    )


def radar_from_message(
    msg: FoxPointCloud, sensor: str, id_names: dict[int, str]
) -> RadarDetections:
    """RadarDetections from a hiyari radar message (``actor_ids`` = the actors hit)."""
    pts, pose = unpack_point_cloud(msg)
    hit, actors = actor_hits(pts["truth_id"], id_names)
    measured = ("range", "range_rate", "azimuth", "elevation", "snr_db", "power_dbm")
    col = {k: pts[k].astype(np.float64) for k in measured}
    return RadarDetections(
        time=msg.timestamp.ToNanoseconds() / 1e9,
        sensor=sensor,
        sensor_to_world=pose,
        hit=hit,
        actor_ids=actors,
        **col,
    )


# ------------------------------------------------------------------ camera
def camera_messages(
    frame: CameraFrame, time_ns: int, image_format: str = "jpeg", jpeg_quality: int = 90
) -> tuple[CompressedImage, CameraCalibration, FrameTransform]:
    """(image, calibration, pose) messages of one camera frame.

    ``image_format`` "jpeg" (lossy, ``jpeg_quality`` 1..100) or "png" (lossless).
    """
    if image_format not in ("jpeg", "png"):
        raise ValueError(f"camera image format must be 'jpeg' or 'png', got {image_format!r}")
    img = np.ascontiguousarray(frame.image)
    if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8:
        raise ValueError(f"camera {frame.sensor!r}: image must be (H, W, 3) uint8 RGB")
    params = [cv2.IMWRITE_JPEG_QUALITY, int(jpeg_quality)] if image_format == "jpeg" else []
    ok, buf = cv2.imencode(
        "." + ("jpg" if image_format == "jpeg" else "png"), img[..., ::-1], params
    )
    if not ok:
        raise ValueError(f"camera {frame.sensor!r}: OpenCV could not encode the image")
    optical = f"{frame.sensor}/optical"
    image = CompressedImage(frame_id=optical, data=buf.tobytes(), format=image_format)
    image.timestamp.FromNanoseconds(time_ns)
    h, w = img.shape[:2]
    k = np.asarray(frame.intrinsics, np.float64)
    p = np.zeros((3, 4))
    p[:, :3] = k
    dist = [float(d) for d in np.asarray(frame.distortion).ravel()]
    calib = CameraCalibration(
        frame_id=optical,
        width=w,
        height=h,
        distortion_model="plumb_bob",
        D=(dist + [0.0] * 5)[: max(5, len(dist))],
        K=k.ravel().tolist(),
        R=np.eye(3).ravel().tolist(),
        P=p.ravel().tolist(),
    )
    calib.timestamp.FromNanoseconds(time_ns)
    s2w = np.asarray(frame.sensor_to_world, np.float64)
    tf = FrameTransform(parent_frame_id=WORLD_FRAME, child_frame_id=optical)
    tf.timestamp.FromNanoseconds(time_ns)
    tf.translation.x, tf.translation.y, tf.translation.z = s2w[:3, 3].tolist()
    q = tf.rotation
    q.w, q.x, q.y, q.z = quat_from_matrix(s2w[:3, :3] @ _BODY_FROM_OPTICAL)
    return image, calib, tf


def camera_from_messages(
    image: CompressedImage,
    calib: CameraCalibration | None,
    tf: FrameTransform | None,
    sensor: str,
    n_distortion: int = 2,
) -> CameraFrame:
    """CameraFrame from its messages (identity pose / unit intrinsics when missing)."""
    bgr = cv2.imdecode(np.frombuffer(image.data, np.uint8), cv2.IMREAD_COLOR)
    if bgr is None:
        raise ValueError(f"camera {sensor!r}: image data is not a valid {image.format}")
    k = np.array(calib.K).reshape(3, 3) if calib is not None and calib.K else np.eye(3)
    dist = np.array(calib.D[:n_distortion]) if calib is not None else np.zeros(n_distortion)
    pose = np.eye(4)
    if tf is not None:
        q = tf.rotation
        pose[:3, :3] = matrix_from_quat(q.w, q.x, q.y, q.z) @ _BODY_FROM_OPTICAL.T
        pose[:3, 3] = (tf.translation.x, tf.translation.y, tf.translation.z)
    return CameraFrame(
        time=image.timestamp.ToNanoseconds() / 1e9,
        sensor=sensor,
        sensor_to_world=pose,
        image=np.ascontiguousarray(bgr[..., ::-1]),
        intrinsics=k,
        distortion=dist,
    )


# ------------------------------------------------------------------ scene updates
def _color(msg: Color, rgb: tuple[int, int, int], alpha: float = 1.0) -> None:
    msg.r, msg.g, msg.b, msg.a = rgb[0] / 255, rgb[1] / 255, rgb[2] / 255, alpha


_XYZ = {"x": None, "y": None, "z": None}
#: One ``cubes`` entry of a SceneEntity (all doubles: a fixed layout, see recording_wire).
_CUBE_LAYOUT = FixedLayout(
    CubePrimitive.DESCRIPTOR,
    {
        "pose": {"position": _XYZ, "orientation": {"x": None, "y": None, "z": None, "w": None}},
        "size": _XYZ,
        "color": {"r": None, "g": None, "b": None, "a": None},
    },
    wrap=(SceneEntity.DESCRIPTOR, "cubes"),
)
_ENTITIES_KEY = key(SceneUpdate.DESCRIPTOR.fields_by_name["entities"].number, 2)


def _cubes(
    entity_id: str,
    time_ns: int,
    centre: np.ndarray,
    yaw: np.ndarray,
    size: np.ndarray,
    colors: np.ndarray,
    alpha: float,
) -> bytes:
    """Serialized SceneUpdate with one entity of boxes (vectorised over boxes)."""
    entity = SceneEntity(id=entity_id, frame_id=WORLD_FRAME)
    entity.timestamp.FromNanoseconds(time_ns)
    q = yaw_quats(yaw)
    rgb = np.asarray(colors, np.float64) / 255.0
    rows = _CUBE_LAYOUT.encode(
        [
            centre[:, 0],
            centre[:, 1],
            centre[:, 2],
            q[:, 1],
            q[:, 2],
            q[:, 3],
            q[:, 0],
            size[:, 0],
            size[:, 1],
            size[:, 2],
            rgb[:, 0],
            rgb[:, 1],
            rgb[:, 2],
            np.full(len(centre), alpha),
        ]
    )
    body = entity.SerializeToString() + rows.tobytes()
    return _ENTITIES_KEY + varint(len(body)) + body


def truth_boxes(state: WorldState, ego_id: str | None, time_ns: int) -> bytes:
    """Ground-truth boxes coloured by class (the ego in EGO_COLOR): a serialized
    ``foxglove.SceneUpdate`` with one entity."""
    centre = state.xyz.copy()
    centre[:, 2] += 0.5 * state.height
    colors = class_colors(state.cls).astype(np.float64)
    if ego_id is not None:
        colors[state.ids == ego_id] = EGO_COLOR
    size = np.stack([state.length, state.width, state.height], 1)
    return _cubes("ground_truth", time_ns, centre, state.heading, size, colors, 1.0)


def object_boxes(
    position_world: np.ndarray, yaw: float, size: np.ndarray, source: str, time_ns: int
) -> bytes:
    """Perceived objects of one source as translucent boxes (unknown sizes drawn as 1 m): a
    serialized ``foxglove.SceneUpdate``."""
    n = len(position_world)
    colors = np.tile(np.array(source_color(source), np.float64), (n, 1))
    size = np.where(np.isfinite(size), size, 1.0)
    return _cubes(f"objects/{source}", time_ns, position_world, np.full(n, yaw), size, colors, 0.5)


def mesh_update(mesh: SceneMesh, time_ns: int) -> SceneUpdate:
    """The static road mesh as one entity, one triangle list per material."""
    update = SceneUpdate()
    e = update.entities.add(id="road_mesh", frame_id=WORLD_FRAME)
    e.timestamp.FromNanoseconds(time_ns)
    for m in np.unique(mesh.material):
        faces = mesh.faces[mesh.material == m]
        used, inverse = np.unique(faces.ravel(), return_inverse=True)
        prim = e.triangles.add()
        prim.pose.orientation.w = 1.0
        _color(prim.color, material_color(int(m)))
        prim.points.extend(Point3(x=x, y=y, z=z) for x, y, z in mesh.vertices[used].tolist())
        prim.indices.extend(inverse.astype(np.uint32).tolist())
    return update
