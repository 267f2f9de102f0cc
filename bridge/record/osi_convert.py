"""WorldState, environment and object lists to ASAM OSI messages (osi3.GroundTruth /
osi3.SensorData), and back.

OSI conventions used: positions are bounding-box centres in the world frame (SUMO network
coordinates, metres), so ``z = ground z + height / 2``; ``orientation.yaw`` is the heading in
radians counter-clockwise from +x; velocity and acceleration are world-frame vectors along the
heading. OSI ids are small integers from an :class:`OsiIdMap`; every moving object's first
``source_reference`` carries its SUMO id (type ``org.eclipse.sumo.vehicle`` or
``org.eclipse.sumo.person``), a second one its SUMO lane and edge (``org.eclipse.sumo.lane``).
Every vehicle (host or not) has ``vehicle_attributes`` from its class and size
(:mod:`hiyari.bridge.record.osi_vehicle`); sensor mounting positions are in OSI's vehicle
frame, whose origin is the host's rear-axle middle (``bbcenter_to_rear``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from osi3 import osi_common_pb2, osi_environment_pb2, osi_version_pb2
from osi3.osi_groundtruth_pb2 import GroundTruth
from osi3.osi_object_pb2 import MovingObject
from osi3.osi_sensordata_pb2 import SensorData

from hiyari.bridge.record.osi_vehicle import vehicle_attributes
from hiyari.bridge.record.wire import FixedLayout, key, splice
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState

_IV = osi_version_pb2.DESCRIPTOR.GetOptions().Extensions[osi_version_pb2.current_interface_version]
#: The OSI interface version of the installed osi3 messages, e.g. "3.8.0".
OSI_VERSION = f"{_IV.version_major}.{_IV.version_minor}.{_IV.version_patch}"

REF_VEHICLE = "org.eclipse.sumo.vehicle"
REF_PERSON = "org.eclipse.sumo.person"
REF_LANE = "org.eclipse.sumo.lane"

_VC = MovingObject.VehicleClassification
_ENV = osi_environment_pb2.EnvironmentalConditions
_TO_OSI_VEHICLE = {
    ActorClass.CAR: _VC.TYPE_MEDIUM_CAR,
    ActorClass.TRUCK: _VC.TYPE_HEAVY_TRUCK,
    ActorClass.BUS: _VC.TYPE_BUS,
    ActorClass.MOTORCYCLE: _VC.TYPE_MOTORBIKE,
    ActorClass.BICYCLE: _VC.TYPE_BICYCLE,
}
_FROM_OSI_VEHICLE = {v: k for k, v in _TO_OSI_VEHICLE.items()} | {
    _VC.TYPE_SMALL_CAR: ActorClass.CAR,
    _VC.TYPE_COMPACT_CAR: ActorClass.CAR,
    _VC.TYPE_LUXURY_CAR: ActorClass.CAR,
    _VC.TYPE_DELIVERY_VAN: ActorClass.TRUCK,
    _VC.TYPE_SEMITRACTOR: ActorClass.TRUCK,
    _VC.TYPE_SEMITRAILER: ActorClass.TRUCK,
    _VC.TYPE_TRAILER: ActorClass.TRUCK,
    _VC.TYPE_TRAM: ActorClass.BUS,
    _VC.TYPE_STANDUP_SCOOTER: ActorClass.BICYCLE,
}

# OSI's discretisation bands (osi_environment.proto): lower bounds of each category.
_PRECIPITATION_BANDS_MM_H = [
    (149.0, _ENV.PRECIPITATION_EXTREME),
    (34.0, _ENV.PRECIPITATION_VERY_HEAVY),
    (8.1, _ENV.PRECIPITATION_HEAVY),
    (1.9, _ENV.PRECIPITATION_MODERATE),
    (0.5, _ENV.PRECIPITATION_LIGHT),
    (0.1, _ENV.PRECIPITATION_VERY_LIGHT),
    (0.0, _ENV.PRECIPITATION_NONE),
]
_FOG_BANDS_M = [
    (40000.0, _ENV.FOG_EXCELLENT_VISIBILITY),
    (10000.0, _ENV.FOG_GOOD_VISIBILITY),
    (4000.0, _ENV.FOG_MODERATE_VISIBILITY),
    (2000.0, _ENV.FOG_POOR_VISIBILITY),
    (1000.0, _ENV.FOG_MIST),
    (200.0, _ENV.FOG_LIGHT),
    (50.0, _ENV.FOG_THICK),
    (0.0, _ENV.FOG_DENSE),
]
_ILLUMINATION_BANDS_LUX = [
    (10000.0, _ENV.AMBIENT_ILLUMINATION_LEVEL9),
    (1000.0, _ENV.AMBIENT_ILLUMINATION_LEVEL8),
    (400.0, _ENV.AMBIENT_ILLUMINATION_LEVEL7),
    (20.0, _ENV.AMBIENT_ILLUMINATION_LEVEL6),
    (10.0, _ENV.AMBIENT_ILLUMINATION_LEVEL5),
    (3.0, _ENV.AMBIENT_ILLUMINATION_LEVEL4),
    (1.0, _ENV.AMBIENT_ILLUMINATION_LEVEL3),
    (0.01, _ENV.AMBIENT_ILLUMINATION_LEVEL2),
    (0.0, _ENV.AMBIENT_ILLUMINATION_LEVEL1),
]

#: Environment fields read from a mapping or object (all optional; units in the names). The
#: names of hiyari.sensors.environment.conditions.Environment are understood too: ``rain_mm_h``,
#: ``sun_azimuth_deg``, ``sun_elevation_deg`` and ``illumination`` ("day", "dusk", "night",
#: with ``street_lights``).
ENVIRONMENT_FIELDS = (
    "precipitation_mm_h",
    "fog_visibility_m",
    "illuminance_lux",
    "time_of_day_s",
    "temperature_k",
    "relative_humidity_pct",
    "atmospheric_pressure_pa",
    "sun_azimuth_rad",
    "sun_elevation_rad",
    "sun_illuminance_lux",
    "unix_timestamp_s",
)
_ALIASES = {"precipitation_mm_h": ("rain_mm_h",)}
_DEGREE_ALIASES = {"sun_azimuth_rad": "sun_azimuth_deg", "sun_elevation_rad": "sun_elevation_deg"}
#: Ambient illuminance of the sensors' lighting-model defaults per time of day, lux: clear-day
#: skylight, civil-twilight skylight, moonless night, night under street lights.
ILLUMINATION_LUX = {"day": 15000.0, "dusk": 300.0, "night": 0.05, "night_lit": 15.0}


class OsiIdMap:
    """Stable SUMO id -> OSI integer id: 1, 2, 3 ... in order of first appearance."""

    def __init__(self) -> None:
        self._ids: dict[str, int] = {}
        self._new: dict[int, str] = {}

    def __len__(self) -> int:
        return len(self._ids)

    def get(self, sumo_id: str) -> int:
        """OSI id of ``sumo_id`` (assigned now if it is new)."""
        osi = self._ids.get(sumo_id)
        if osi is None:
            osi = self._ids[sumo_id] = len(self._ids) + 1
            self._new[osi] = sumo_id
        return osi

    def get_many(self, sumo_ids: Sequence[str]) -> list[int]:
        """OSI ids of several SUMO ids, in order."""
        found = list(map(self._ids.get, sumo_ids))
        if None in found:
            found = [self.get(s) for s in sumo_ids]
        return found

    def take_new(self) -> dict[int, str]:
        """Ids assigned since the last call (OSI id -> SUMO id)."""
        new, self._new = self._new, {}
        return new


def interface_version() -> osi_version_pb2.InterfaceVersion:
    """The installed OSI interface version as a message."""
    return osi_version_pb2.InterfaceVersion(
        version_major=_IV.version_major,
        version_minor=_IV.version_minor,
        version_patch=_IV.version_patch,
    )


def set_timestamp(ts: osi_common_pb2.Timestamp, ns: int) -> None:
    """Fill an OSI Timestamp from integer nanoseconds."""
    ts.seconds, ts.nanos = divmod(ns, 1_000_000_000)


def timestamp_ns(ts: osi_common_pb2.Timestamp) -> int:
    """Integer nanoseconds of an OSI Timestamp."""
    return ts.seconds * 1_000_000_000 + ts.nanos


_XYZ_SPEC = {"x": None, "y": None, "z": None}
#: The all-double part of a moving object: its BaseMoving (13 doubles, fixed layout).
_BASE_LAYOUT = FixedLayout(
    MovingObject.DESCRIPTOR,
    {
        "base": {
            "dimension": {"length": None, "width": None, "height": None},
            "position": _XYZ_SPEC,
            "orientation": {"yaw": None},
            "velocity": _XYZ_SPEC,
            "acceleration": _XYZ_SPEC,
        }
    },
)
_MOVING_OBJECT_KEY = key(GroundTruth.DESCRIPTOR.fields_by_name["moving_object"].number, 2)


class GroundTruthEncoder:
    """Encodes WorldStates as serialized ``osi3.GroundTruth``, vectorised over actors.

    Each moving object is its BaseMoving (numpy, see recording_wire) followed by the parts
    that change rarely (OSI id, type, classification, vehicle attributes, SUMO references),
    which are encoded with the protobuf library once per actor, lane and size and cached.
    """

    def __init__(self) -> None:
        self._tails: dict[tuple, bytes] = {}

    def encode(
        self,
        state: WorldState,
        osi_ids: Sequence[int],
        time_ns: int,
        ego_osi_id: int | None = None,
        environment: Any = None,
    ) -> bytes:
        """Serialized GroundTruth of ``state`` (``osi_ids`` row by row), see
        :func:`ground_truth_message`."""
        gt = GroundTruth()
        gt.version.CopyFrom(interface_version())
        set_timestamp(gt.timestamp, time_ns)
        if ego_osi_id is not None:
            gt.host_vehicle_id.value = ego_osi_id
        if environment is not None:
            fill_environment(gt.environmental_conditions, environment)
        head = gt.SerializeToString()
        if len(state) == 0:
            return head
        c, s = np.cos(state.heading), np.sin(state.heading)
        rows = _BASE_LAYOUT.encode(
            [
                state.length,
                state.width,
                state.height,
                state.xyz[:, 0],
                state.xyz[:, 1],
                state.xyz[:, 2] + 0.5 * state.height,
                state.heading,
                state.speed * c,
                state.speed * s,
                np.zeros(len(state)),
                state.accel * c,
                state.accel * s,
                np.zeros(len(state)),
            ]
        )
        keys = list(
            zip(
                state.ids.tolist(),
                state.lane.tolist(),
                state.edge.tolist(),
                state.cls.tolist(),
                list(osi_ids),
                state.length.tolist(),
                state.width.tolist(),
                state.height.tolist(),
                strict=True,
            )
        )
        cache = self._tails
        tails = [cache.get(k) or _tail(*k) for k in keys]
        self._tails = dict(zip(keys, tails, strict=True))  # only actors still present
        return head + splice(_MOVING_OBJECT_KEY, rows, tails)


def _tail(sumo_id: str, lane: str, edge: str, cls: int, osi_id: int, length: float,
          width: float, height: float) -> bytes:  # fmt: skip
    """The non-double fields of one moving object, serialized."""
    m = MovingObject()
    m.id.value = osi_id
    if cls == ActorClass.PEDESTRIAN:
        m.type = MovingObject.TYPE_PEDESTRIAN
        m.source_reference.add(type=REF_PERSON, identifier=[sumo_id])
    else:
        m.type = MovingObject.TYPE_VEHICLE
        m.vehicle_attributes.CopyFrom(vehicle_attributes(cls, length, width, height))
        m.vehicle_classification.type = _TO_OSI_VEHICLE.get(cls, _VC.TYPE_OTHER)
        m.vehicle_classification.role = _VC.ROLE_CIVIL
        m.source_reference.add(type=REF_VEHICLE, identifier=[sumo_id])
    if lane or edge:
        m.source_reference.add(type=REF_LANE, identifier=[lane, edge])
    return m.SerializeToString()


def vehicle_pose(x: float, y: float, z: float, heading: float) -> np.ndarray:
    """(4, 4) vehicle frame (origin at the ground-rectangle centre, x forward) to world."""
    c, s = math.cos(heading), math.sin(heading)
    pose = np.eye(4)
    pose[:2, :2] = [[c, -s], [s, c]]
    pose[:3, 3] = (x, y, z)
    return pose


def ground_truth_message(
    state: WorldState,
    osi_ids: Sequence[int],
    time_ns: int,
    ego_osi_id: int | None = None,
    environment: Any = None,
) -> GroundTruth:
    """One ``osi3.GroundTruth`` for a WorldState (``osi_ids`` row by row)."""
    data = GroundTruthEncoder().encode(state, osi_ids, time_ns, ego_osi_id, environment)
    return GroundTruth.FromString(data)


def world_state_from_ground_truth(
    gt: GroundTruth, id_names: Mapping[int, str] | None = None
) -> tuple[WorldState, str | None]:
    """(WorldState, ego SUMO id or None) from an ``osi3.GroundTruth``.

    SUMO ids come from each object's source reference, else from ``id_names``, else the OSI
    id as text. ``xyz`` is converted back to the ground-rectangle centre.
    """
    objs = gt.moving_object
    n = len(objs)
    names = id_names or {}
    ids, lanes, edges = [], [], []
    cls = np.zeros(n, np.int8)
    num = np.zeros((n, 12))  # x y z yaw vx vy ax ay l w h osi_id
    for i, m in enumerate(objs):
        b = m.base
        p, v, a, d = b.position, b.velocity, b.acceleration, b.dimension
        num[i] = (
            p.x,
            p.y,
            p.z,
            b.orientation.yaw,
            v.x,
            v.y,
            a.x,
            a.y,
            d.length,
            d.width,
            d.height,
            m.id.value,
        )
        sumo_id, lane, edge = "", "", ""
        for ref in m.source_reference:
            if ref.type in (REF_VEHICLE, REF_PERSON) and ref.identifier:
                sumo_id = ref.identifier[0]
            elif ref.type == REF_LANE and len(ref.identifier) == 2:
                lane, edge = ref.identifier
        ids.append(sumo_id or names.get(m.id.value, str(m.id.value)))
        lanes.append(lane)
        edges.append(edge)
        cls[i] = _actor_class(m.type, m.vehicle_classification.type)
    heading = num[:, 3]
    c, s = np.cos(heading), np.sin(heading)
    xyz = num[:, 0:3].copy()
    xyz[:, 2] -= 0.5 * num[:, 10]
    state = WorldState(
        time=timestamp_ns(gt.timestamp) / 1e9,
        ids=np.array(ids, dtype=object),
        cls=cls,
        xyz=xyz,
        heading=heading,
        speed=num[:, 4] * c + num[:, 5] * s,
        accel=num[:, 6] * c + num[:, 7] * s,
        length=num[:, 8],
        width=num[:, 9],
        height=num[:, 10],
        lane=np.array(lanes, dtype=object),
        edge=np.array(edges, dtype=object),
    )
    ego = None
    if gt.HasField("host_vehicle_id"):
        hits = np.flatnonzero(num[:, 11] == gt.host_vehicle_id.value)
        ego = str(state.ids[hits[0]]) if hits.size else None
    return state, ego


def _actor_class(osi_type: int, vehicle_type: int) -> int:
    if osi_type == MovingObject.TYPE_PEDESTRIAN:
        return int(ActorClass.PEDESTRIAN)
    if osi_type == MovingObject.TYPE_VEHICLE:
        return int(_FROM_OSI_VEHICLE.get(vehicle_type, ActorClass.CAR))
    return -1


def _band(value: float, bands: list[tuple[float, int]]) -> int:
    for lower, category in bands:
        if value >= lower:
            return category
    return bands[-1][1]


def _lookup(env: Any, name: str) -> Any:
    return env.get(name) if isinstance(env, Mapping) else getattr(env, name, None)


def _env_value(env: Any, name: str) -> float | None:
    value = _lookup(env, name)
    for alias in _ALIASES.get(name, ()):
        value = _lookup(env, alias) if value is None else value
    if value is None and name in _DEGREE_ALIASES:
        deg = _lookup(env, _DEGREE_ALIASES[name])
        value = None if deg is None else math.radians(float(deg))
    if value is None and name == "illuminance_lux":
        light = _lookup(env, "illumination")
        if light is not None:
            key = str(getattr(light, "value", light))
            lit = key == "night" and bool(_lookup(env, "street_lights"))
            value = ILLUMINATION_LUX.get("night_lit" if lit else key)
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) or name == "fog_visibility_m" else None


def fill_environment(msg: osi_environment_pb2.EnvironmentalConditions, env: Any) -> None:
    """Fill OSI EnvironmentalConditions from a mapping or object with ENVIRONMENT_FIELDS.

    Rain rate, visibility and illuminance are stored as OSI's categories; the rest as values.
    An ``osi3.EnvironmentalConditions`` is copied as it is.
    """
    if isinstance(env, osi_environment_pb2.EnvironmentalConditions):
        msg.CopyFrom(env)
        return
    get = {name: _env_value(env, name) for name in ENVIRONMENT_FIELDS}
    if get["precipitation_mm_h"] is not None:
        msg.precipitation = _band(get["precipitation_mm_h"], _PRECIPITATION_BANDS_MM_H)
    if get["fog_visibility_m"] is not None:
        msg.fog = _band(get["fog_visibility_m"], _FOG_BANDS_M)
    if get["illuminance_lux"] is not None:
        msg.ambient_illumination = _band(get["illuminance_lux"], _ILLUMINATION_BANDS_LUX)
    if get["time_of_day_s"] is not None:
        msg.time_of_day.seconds_since_midnight = int(get["time_of_day_s"]) % 86400
    if get["temperature_k"] is not None:
        msg.temperature = get["temperature_k"]
    if get["relative_humidity_pct"] is not None:
        msg.relative_humidity = get["relative_humidity_pct"]
    if get["atmospheric_pressure_pa"] is not None:
        msg.atmospheric_pressure = get["atmospheric_pressure_pa"]
    if get["unix_timestamp_s"] is not None:
        msg.unix_timestamp = int(get["unix_timestamp_s"])
    for field, name in (
        ("azimuth", "sun_azimuth_rad"),
        ("elevation", "sun_elevation_rad"),
        ("intensity", "sun_illuminance_lux"),
    ):
        if get[name] is not None:
            setattr(msg.sun, field, get[name])


def environment_summary(msg: osi_environment_pb2.EnvironmentalConditions) -> dict[str, str]:
    """Readable categories of OSI EnvironmentalConditions (only the fields that are set)."""
    out: dict[str, str] = {}
    for field, enum, prefix in (
        ("precipitation", _ENV.Precipitation, "PRECIPITATION_"),
        ("fog", _ENV.Fog, "FOG_"),
        ("ambient_illumination", _ENV.AmbientIllumination, "AMBIENT_ILLUMINATION_"),
    ):
        if msg.HasField(field):
            out[field] = enum.Name(getattr(msg, field)).removeprefix(prefix).lower()
    if msg.HasField("temperature"):
        out["temperature"] = f"{msg.temperature - 273.15:.1f} °C"
    if msg.HasField("sun"):
        out["sun_elevation"] = f"{math.degrees(msg.sun.elevation):.0f}°"
    return out


# ------------------------------------------------------------------ object lists
def set_pose(pose: np.ndarray, base: Any) -> None:
    """A 4x4 frame-to-world pose as position + roll/pitch/yaw (Z-Y-X intrinsic), into any
    message with ``position`` and ``orientation`` (BaseMoving, MountingPosition)."""
    r = pose[:3, :3]
    base.position.x, base.position.y, base.position.z = pose[:3, 3].tolist()
    base.orientation.yaw = math.atan2(r[1, 0], r[0, 0])
    base.orientation.pitch = math.asin(-max(-1.0, min(1.0, r[2, 0])))
    base.orientation.roll = math.atan2(r[2, 1], r[2, 2])


def pose_of(base: Any) -> np.ndarray:
    o = base.orientation
    cy, sy = math.cos(o.yaw), math.sin(o.yaw)
    cp, sp = math.cos(o.pitch), math.sin(o.pitch)
    cr, sr = math.cos(o.roll), math.sin(o.roll)
    pose = np.eye(4)
    pose[:3, :3] = [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
    pose[:3, 3] = (base.position.x, base.position.y, base.position.z)
    return pose


def _set_finite(vec: Any, fields: tuple[str, str, str], values: list[float]) -> None:
    for f, v in zip(fields, values, strict=True):
        if math.isfinite(v):
            setattr(vec, f, v)


def _get_or_nan(vec: Any, fields: tuple[str, str, str]) -> tuple[float, ...]:
    return tuple(getattr(vec, f) if vec.HasField(f) else math.nan for f in fields)


_XYZ = ("x", "y", "z")
_LWH = ("length", "width", "height")


def sensor_data_message(
    objects: ObjectList,
    sensor_id: int,
    truth_osi_ids: Sequence[int | None],
    time_ns: int,
    host: tuple[np.ndarray, Sequence[float]] | None = None,
) -> SensorData:
    """One ``osi3.SensorData`` for an object list.

    ``host``: (vehicle frame to world (4, 4), origin at the centre of the ground rectangle;
    (length, width, height) m; ``bbcenter_to_rear`` (3,) m) of the ego at this time. With it,
    ``host_vehicle_location`` is the ego's bounding box (centre pose and dimension, as OSI's
    BaseMoving) and ``mounting_position`` the list's frame in OSI's vehicle frame (origin at
    the rear-axle middle, the box centre + ``bbcenter_to_rear``, as the host's
    ``vehicle_attributes`` in the ground truth say), so world = box pose, then
    ``bbcenter_to_rear``, then mounting, applied to each object. Without it the host location
    is the list's frame itself and the mounting the identity.
    Track / detection ids go to ``header.tracking_id``, confidence to
    ``existence_probability``, the truth to ``ground_truth_id``; components that are nan are
    left unset.
    """
    if len(objects) and int(np.min(objects.object_id)) < 0:
        raise ValueError(f"object list {objects.source!r}: object ids must be >= 0")
    sd = SensorData()
    sd.version.CopyFrom(interface_version())
    set_timestamp(sd.timestamp, time_ns)
    set_timestamp(sd.last_measurement_time, time_ns)
    sd.sensor_id.value = sensor_id
    frame = np.asarray(objects.frame_to_world, np.float64)
    if host is None:
        set_pose(frame, sd.host_vehicle_location)
        sd.mounting_position.position.x = 0.0
    else:
        vehicle, (length, width, height) = np.asarray(host[0], np.float64), host[1]
        centre = vehicle.copy()
        centre[:3, 3] += vehicle[:3, 2] * (0.5 * height)
        set_pose(centre, sd.host_vehicle_location)
        d = sd.host_vehicle_location.dimension
        d.length, d.width, d.height = float(length), float(width), float(height)
        set_pose(np.linalg.solve(_offset(centre, host[2]), frame), sd.mounting_position)
    pos, vel, size = objects.position.tolist(), objects.velocity.tolist(), objects.size.tolist()
    conf, oid, cls = objects.confidence.tolist(), objects.object_id.tolist(), objects.cls.tolist()
    for i in range(len(objects)):
        d = sd.moving_object.add()
        h = d.header
        h.tracking_id.value = oid[i]
        h.existence_probability = conf[i]
        h.sensor_id.add(value=sensor_id)
        if truth_osi_ids[i] is not None:
            h.ground_truth_id.add(value=truth_osi_ids[i])
        _set_finite(d.base.position, _XYZ, pos[i])
        _set_finite(d.base.velocity, _XYZ, vel[i])
        _set_finite(d.base.dimension, _LWH, size[i])
        if cls[i] >= 0:
            cand = d.candidate.add(probability=1.0)
            if cls[i] == ActorClass.PEDESTRIAN:
                cand.type = MovingObject.TYPE_PEDESTRIAN
            else:
                cand.type = MovingObject.TYPE_VEHICLE
                cand.vehicle_classification.type = _TO_OSI_VEHICLE.get(cls[i], _VC.TYPE_OTHER)
    return sd


def _offset(pose: np.ndarray, vector: Sequence[float]) -> np.ndarray:
    """``pose`` moved by ``vector`` given in its own frame."""
    out = pose.copy()
    out[:3, 3] += pose[:3, :3] @ np.asarray(vector, np.float64)
    return out


def object_list_from_sensor_data(
    sd: SensorData,
    source: str,
    id_names: Mapping[int, str],
    bbcenter_to_rear: Sequence[float] | None = None,
) -> ObjectList:
    """ObjectList from an ``osi3.SensorData`` (``id_names``: OSI id -> SUMO id).
    ``bbcenter_to_rear``: the host's, from the ground truth of the same time (None: the
    centre of the host's ground rectangle, as recordings before format 4 have it)."""
    objs = sd.moving_object
    n = len(objs)
    position, velocity, size = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    object_id, cls = np.zeros(n, np.int64), np.full(n, -1, np.int8)
    confidence, truth = np.zeros(n), np.full(n, "", dtype=object)
    for i, d in enumerate(objs):
        h = d.header
        object_id[i] = h.tracking_id.value
        confidence[i] = h.existence_probability
        if h.ground_truth_id:
            gid = h.ground_truth_id[0].value
            truth[i] = id_names.get(gid, str(gid))
        position[i] = _get_or_nan(d.base.position, _XYZ)
        velocity[i] = _get_or_nan(d.base.velocity, _XYZ)
        size[i] = _get_or_nan(d.base.dimension, _LWH)
        if d.candidate:
            c = d.candidate[0]
            cls[i] = _actor_class(c.type, c.vehicle_classification.type)
    host = sd.host_vehicle_location
    if bbcenter_to_rear is None or not host.HasField("dimension"):  # no host: no offset
        bbcenter_to_rear = (0.0, 0.0, -0.5 * host.dimension.height)  # 0 without a dimension
    vehicle = _offset(pose_of(host), bbcenter_to_rear)
    return ObjectList(
        time=timestamp_ns(sd.timestamp) / 1e9,
        source=source,
        frame_to_world=vehicle @ pose_of(sd.mounting_position),
        object_id=object_id,
        cls=cls,
        position=position,
        velocity=velocity,
        size=size,
        confidence=confidence,
        truth=truth,
    )
