"""The OSI GroundTruth of a real recording, field by field against the OSI 3.x proto docs, read
with asam-osi-utilities' trace reader: every vehicle's vehicle_attributes from its size (hand
computed), no *_UNKNOWN enum value (OSI: "must not be used in ground truth"), ids unique, and
every field written is the list in docs/osi_fields.md, whose unset lists are exactly the
other fields of each message written."""

from __future__ import annotations

import re

import numpy as np
import pytest
from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.message import Message
from osi3.osi_groundtruth_pb2 import GroundTruth
from osi3.osi_object_pb2 import MovingObject
from osi3.osi_sensordata_pb2 import SensorData
from osi3.osi_sensorview_pb2 import SensorView
from osi_utilities import MultiTraceReader
from paths import REPO_ROOT

from hiyari.bridge.record.recorder import Recorder, RecorderConfig, SensorMount
from hiyari.net.mesh.road_mesh import build_scene_mesh
from hiyari.net.road.geometry import RoadGeometry
from hiyari.sensors.frames import Mount
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic import ActorClass, SimConfig, Simulation

DOC = REPO_ROOT / "docs" / "osi_fields.md"
ROOTS = {"GroundTruth": GroundTruth, "SensorData": SensorData, "SensorView": SensorView}
#: (front overhang, rear overhang, wheel radius / height, track / width) per class, from
#: published dimensions (osi_vehicle.AXLES): the car's rear axle 0.18 L from its rear end
CAR, TRUCK, BUS, MOTORCYCLE = (
    ActorClass.CAR,
    ActorClass.TRUCK,
    ActorClass.BUS,
    ActorClass.MOTORCYCLE,
)
LAYOUT = {
    CAR: (0.21, 0.18, 0.21, 0.86),
    TRUCK: (0.16, 0.27, 0.14, 0.80),
    BUS: (0.23, 0.28, 0.15, 0.84),
    MOTORCYCLE: (0.18, 0.16, 0.20, 0.0),
}
CLEARANCE = {CAR: 0.12, TRUCK: 0.1, BUS: 0.1, MOTORCYCLE: 0.12}  # of the height: ray-cast body
OSI_CLASS = {
    MovingObject.VehicleClassification.TYPE_MEDIUM_CAR: CAR,
    MovingObject.VehicleClassification.TYPE_HEAVY_TRUCK: TRUCK,
    MovingObject.VehicleClassification.TYPE_BUS: BUS,
    MovingObject.VehicleClassification.TYPE_MOTORBIKE: MOTORCYCLE,
}


#: Every environment field the recorder writes (osi_convert.ENVIRONMENT_FIELDS).
ENVIRONMENT = {
    "precipitation_mm_h": 2.0, "fog_visibility_m": 800.0, "illuminance_lux": 15000.0,
    "time_of_day_s": 43200.0, "temperature_k": 293.15, "relative_humidity_pct": 60.0,
    "atmospheric_pressure_pa": 101325.0, "sun_azimuth_rad": 1.0, "sun_elevation_rad": 0.5,
    "sun_illuminance_lux": 90000.0, "unix_timestamp_s": 1767225600.0,
}  # fmt: skip


@pytest.fixture(scope="module")
def trace(intersection_net, intersection_demand, tmp_path_factory) -> dict[str, list[Message]]:
    """50 s on the signalised intersection (cars, trucks, buses, motorcycles, pedestrians),
    the road and its lights, an environment, a host vehicle with a mounted sensor's object
    list; read back with asam-osi-utilities, by message type."""
    out = tmp_path_factory.mktemp("osi_fields") / "fields.mcap"
    geometry = RoadGeometry.from_net(intersection_net)
    mount = Mount(x=2.0, z=1.2)
    with (
        Simulation(SimConfig(net=intersection_net, routes=[intersection_demand], seed=5)) as sim,
        Recorder(out, {"scenario": "fields"}, RecorderConfig(creation_time="2026-01-01T00:00:00Z")) as rec,
    ):  # fmt: skip
        rec.write_road(geometry, build_scene_mesh(geometry, buildings=True), sim.signal_links())
        rec.add_sensor_config("front", {}, SensorMount("radar", mount.sensor_to_ego(), 1.0, 0.2))
        host = None
        for state in sim.run(until=50.0):
            cars = [i for i, c in zip(state.ids, state.cls, strict=True) if c == CAR]
            host = host if host in state.ids else (cars[0] if cars else None)
            env = ENVIRONMENT
            rec.write_world(state, host, env, signals=sim.signal_states())
            if host is not None:
                r = int(np.flatnonzero(state.ids == host)[0])
                rec.write_objects(_objects(state, r, mount))
    reader = MultiTraceReader()
    assert reader.open(out)
    messages: dict[str, list[Message]] = {}
    try:
        for record in reader:
            messages.setdefault(type(record.message).__name__, []).append(record.message)
    finally:
        reader.close()
    return messages


def _objects(state, r: int, mount: Mount) -> ObjectList:
    """One detection of the host itself 10 m ahead of the sensor (fields, not sensing)."""
    c, s = np.cos(state.heading[r]), np.sin(state.heading[r])
    vehicle = np.eye(4)
    vehicle[:2, :2] = [[c, -s], [s, c]]
    vehicle[:3, 3] = state.xyz[r]
    return ObjectList(
        time=state.time, source="front", frame_to_world=vehicle @ mount.sensor_to_ego(),
        object_id=np.array([7]), cls=np.array([CAR], np.int8),
        position=np.array([[10.0, 0.0, 0.0]]), velocity=np.array([[0.0, 0.0, 0.0]]),
        size=np.array([[4.5, 1.8, 1.5]]), confidence=np.array([0.9]),
        truth=np.array([state.ids[r]], dtype=object),
    )  # fmt: skip


def field_paths(msg: Message, prefix: str = "") -> set[str]:
    """Dotted paths of every field set in ``msg`` (repeated ones once)."""
    out = set()
    for fd, value in msg.ListFields():
        path = f"{prefix}.{fd.name}" if prefix else fd.name
        out.add(path)
        if fd.type == FieldDescriptor.TYPE_MESSAGE:
            for item in value if fd.is_repeated else [value]:
                out |= field_paths(item, path)
    return out


def documented() -> dict[str, dict[str, set[str]]]:
    """docs/osi_fields.md: per root message, {"written": paths, "unset": paths}."""
    doc: dict[str, dict[str, set[str]]] = {}
    root = kind = None
    for line in DOC.read_text().splitlines():
        if m := re.match(r"^## (\w+)", line):
            root = m.group(1) if m.group(1) in ROOTS else None
        elif m := re.match(r"^### (Written|Left unset)", line):
            kind = "written" if m.group(1) == "Written" else "unset"
        elif root and kind and (m := re.match(r"^- `([\w.]+)`", line)):
            doc.setdefault(root, {"written": set(), "unset": set()})[kind].add(m.group(1))
    return doc


def _descriptor(root: type[Message], path: str):
    d = root.DESCRIPTOR
    for name in path.split(".") if path else []:
        d = d.fields_by_name[name].message_type
    return d


def test_every_vehicle_has_its_attributes_from_its_size(trace):
    seen: set[int] = set()
    for gt in trace["GroundTruth"]:
        for m in gt.moving_object:
            d = m.base.dimension
            assert d.length > 0 and d.width > 0 and d.height > 0
            if m.type == MovingObject.TYPE_PEDESTRIAN:
                assert not m.HasField("vehicle_attributes")
                assert not m.HasField("vehicle_classification")
                continue
            assert m.type == MovingObject.TYPE_VEHICLE
            cls = OSI_CLASS[m.vehicle_classification.type]
            seen.add(cls)
            front, rear, radius, track = LAYOUT[cls]
            va = m.vehicle_attributes
            axle_z = radius * d.height - d.height / 2  # wheel centres, from the box centre
            b2r, b2f = va.bbcenter_to_rear, va.bbcenter_to_front
            assert (b2r.x, b2r.y, b2r.z) == pytest.approx(
                (rear * d.length - d.length / 2, 0, axle_z)
            )
            assert (b2f.x, b2f.y, b2f.z) == pytest.approx(
                (d.length / 2 - front * d.length, 0, axle_z)
            )
            assert va.ground_clearance == pytest.approx(CLEARANCE[cls] * d.height)
            assert va.number_wheels == len(va.wheel_data) == (4 if track else 2)
            wheels = {(w.axle, w.index): w for w in va.wheel_data}
            for (axle, index), w in wheels.items():
                x = b2f.x if axle == 0 else b2r.x  # OSI: axle 0 is the front-most
                y = (index - 0.5) * track * d.width if track else 0.0  # right to left
                assert (w.position.x, w.position.y, w.position.z) == pytest.approx((x, y, axle_z))
                assert w.wheel_radius == pytest.approx(radius * d.height)
                # the tyre stands on the ground (the bottom of the box)
                assert w.position.z - w.wheel_radius == pytest.approx(-d.height / 2)
    assert seen == {CAR, TRUCK, BUS, MOTORCYCLE}
    # the car: 4.5 m long, its rear axle 1.44 m behind the box centre (not 0)
    host = trace["GroundTruth"][-1]
    (ego,) = [m for m in host.moving_object if m.id.value == host.host_vehicle_id.value]
    assert ego.vehicle_attributes.bbcenter_to_rear.x == pytest.approx(-1.44)


def _enums(msg: Message, path: str = "") -> list[tuple[str, str]]:
    out = []
    for fd, value in msg.ListFields():
        p = f"{path}.{fd.name}" if path else fd.name
        values = value if fd.is_repeated else [value]
        if fd.type == FieldDescriptor.TYPE_ENUM:
            out += [(p, fd.enum_type.values_by_number[v].name) for v in values]
        elif fd.type == FieldDescriptor.TYPE_MESSAGE:
            for item in values:
                out += _enums(item, p)
    return out


def test_ground_truth_follows_the_osi_rules(trace):
    gts = trace["GroundTruth"]
    assert len(gts) == 500 and all(gt.version.version_major == 3 for gt in gts)
    times = [gt.timestamp.seconds + gt.timestamp.nanos / 1e9 for gt in gts]
    np.testing.assert_allclose(times, np.arange(1, 501) * 0.1, atol=1e-9)
    assert sum(gt.HasField("host_vehicle_id") for gt in gts) > 400
    road = gts[0]
    assert len(road.lane) and len(road.lane_boundary)  # stationary objects: none on this road
    for gt in gts[::20]:
        ids = [o.id.value for group in (gt.moving_object, gt.lane, gt.lane_boundary,
               gt.stationary_object, gt.traffic_light) for o in group]  # fmt: skip
        assert len(ids) == len(set(ids)), "OSI ids are globally unique"
        if gt.HasField("host_vehicle_id"):  # from the first car on
            assert gt.host_vehicle_id.value in {m.id.value for m in gt.moving_object}
        assert len(gt.traffic_light) > 0
        unknown = [(p, v) for p, v in _enums(gt) if v.endswith("_UNKNOWN")]
        assert unknown == [], "OSI: *_UNKNOWN must not be used in ground truth"


def test_the_fields_written_are_the_documented_ones(trace):
    doc = documented()
    assert set(doc) == set(ROOTS)
    for name, root in ROOTS.items():
        written, unset = doc[name]["written"], doc[name]["unset"]
        recorded = set().union(*(field_paths(m) for m in trace[name]))
        # the run writes every documented field and nothing else, but for the stationary
        # objects (guard rails, buildings: test_recording_osi_road), which this road has not
        missing = {p for p in written - recorded if not p.startswith("stationary_object")}
        assert recorded <= written and not missing, (sorted(recorded - written), sorted(missing))
        # every other field of each message written is listed as unset
        others = set()
        for path in [""] + [p for p in written if _descriptor(root, p) is not None]:
            for fd in _descriptor(root, path).fields:
                full = f"{path}.{fd.name}" if path else fd.name
                if full not in written:
                    others.add(full)
        assert unset == others, (sorted(unset - others), sorted(others - unset))
