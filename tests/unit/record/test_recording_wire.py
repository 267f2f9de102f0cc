"""The numpy wire encoder against the protobuf library: the same messages, field by field."""

from __future__ import annotations

import numpy as np
import pytest
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from osi3.osi_groundtruth_pb2 import GroundTruth
from osi3.osi_object_pb2 import MovingObject

from hiyari.bridge.record.foxglove_convert import truth_boxes
from hiyari.bridge.record.osi_convert import GroundTruthEncoder, interface_version
from hiyari.bridge.record.osi_vehicle import vehicle_attributes
from hiyari.bridge.record.wire import splice, varint
from hiyari.traffic import ActorClass, WorldState


def _state(n: int, rng: np.random.Generator, long_ids: bool = False) -> WorldState:
    names = [("x" * 150 if long_ids and i % 3 == 0 else "veh") + str(i) for i in range(n)]
    return WorldState(
        time=12.3,
        ids=np.array(names, dtype=object),
        cls=rng.integers(0, 6, n).astype(np.int8),
        xyz=rng.normal(0, 100, (n, 3)),
        heading=rng.uniform(-np.pi, np.pi, n),
        speed=rng.uniform(0, 30, n),
        accel=rng.normal(0, 2, n),
        length=rng.uniform(0.3, 12, n),
        width=rng.uniform(0.5, 2.5, n),
        height=rng.uniform(1.2, 3.5, n),
        lane=np.array([f"e{i}_0" if i % 4 else "" for i in range(n)], dtype=object),
        edge=np.array([f"e{i}" if i % 4 else "" for i in range(n)], dtype=object),
    )


def _reference(state: WorldState, osi_ids: list[int], ns: int, ego: int | None) -> GroundTruth:
    """The same GroundTruth built field by field with the protobuf library."""
    gt = GroundTruth()
    gt.version.CopyFrom(interface_version())
    gt.timestamp.seconds, gt.timestamp.nanos = divmod(ns, 10**9)
    if ego is not None:
        gt.host_vehicle_id.value = ego
    vc = MovingObject.VehicleClassification
    osi_type = {
        0: vc.TYPE_MEDIUM_CAR,
        1: vc.TYPE_HEAVY_TRUCK,
        2: vc.TYPE_BUS,
        3: vc.TYPE_MOTORBIKE,
        4: vc.TYPE_BICYCLE,
    }
    for i in range(len(state)):
        m = gt.moving_object.add()
        m.id.value = osi_ids[i]
        b = m.base
        b.dimension.length, b.dimension.width = state.length[i], state.width[i]
        b.dimension.height = state.height[i]
        b.position.x, b.position.y = state.xyz[i, 0], state.xyz[i, 1]
        b.position.z = state.xyz[i, 2] + 0.5 * state.height[i]
        b.orientation.yaw = state.heading[i]
        c, s = np.cos(state.heading[i]), np.sin(state.heading[i])
        b.velocity.x, b.velocity.y, b.velocity.z = state.speed[i] * c, state.speed[i] * s, 0.0
        b.acceleration.x, b.acceleration.y = state.accel[i] * c, state.accel[i] * s
        b.acceleration.z = 0.0
        if state.cls[i] == ActorClass.PEDESTRIAN:
            m.type = MovingObject.TYPE_PEDESTRIAN
            m.source_reference.add(type="org.eclipse.sumo.person", identifier=[state.ids[i]])
        else:
            m.type = MovingObject.TYPE_VEHICLE
            m.vehicle_attributes.CopyFrom(
                vehicle_attributes(
                    int(state.cls[i]), state.length[i], state.width[i], state.height[i]
                )
            )
            m.vehicle_classification.type = osi_type[int(state.cls[i])]
            m.vehicle_classification.role = vc.ROLE_CIVIL
            m.source_reference.add(type="org.eclipse.sumo.vehicle", identifier=[state.ids[i]])
        if state.lane[i] or state.edge[i]:
            m.source_reference.add(
                type="org.eclipse.sumo.lane", identifier=[state.lane[i], state.edge[i]]
            )
    return gt


@pytest.mark.parametrize("long_ids", [False, True])
def test_ground_truth_encoder_matches_protobuf(long_ids):
    rng = np.random.default_rng(1)
    state = _state(60, rng, long_ids)
    # ids across the one-, two- and three-byte varint ranges
    osi_ids = [int(v) for v in rng.choice([1, 127, 128, 16383, 16384, 2**40], 60)]
    enc = GroundTruthEncoder()
    for _ in range(2):  # second pass reuses the cached per-actor parts
        data = enc.encode(state, osi_ids, 12_300_000_000, ego_osi_id=osi_ids[5])
        assert GroundTruth.FromString(data) == _reference(
            state, osi_ids, 12_300_000_000, osi_ids[5]
        )


def test_empty_state_and_splice_lengths():
    rng = np.random.default_rng(2)
    empty = _state(0, rng)
    gt = GroundTruth.FromString(GroundTruthEncoder().encode(empty, [], 5))
    assert len(gt.moving_object) == 0 and gt.timestamp.nanos == 5
    assert splice(b"\x2a", np.zeros((0, 4), np.uint8), []) == b""
    with pytest.raises(ValueError, match="16 KiB"):
        splice(b"\x2a", np.zeros((1, 4), np.uint8), [bytes(20000)])
    assert varint(300) == b"\xac\x02" and varint(0) == b"\x00"


def test_truth_boxes_match_state():
    rng = np.random.default_rng(3)
    state = _state(25, rng)
    update = SceneUpdate.FromString(truth_boxes(state, "veh4", 7))
    (entity,) = update.entities
    assert entity.id == "ground_truth" and entity.frame_id == "world"
    assert entity.timestamp.ToNanoseconds() == 7
    assert len(entity.cubes) == 25
    for i, cube in enumerate(entity.cubes):
        p, q = cube.pose.position, cube.pose.orientation
        assert (p.x, p.y) == (state.xyz[i, 0], state.xyz[i, 1])
        assert p.z == state.xyz[i, 2] + 0.5 * state.height[i]
        assert np.isclose(2 * np.arctan2(q.z, q.w), state.heading[i]) or np.isclose(
            abs(2 * np.arctan2(q.z, q.w) - state.heading[i]), 2 * np.pi
        )
        assert (cube.size.x, cube.size.y, cube.size.z) == (
            state.length[i],
            state.width[i],
            state.height[i],
        )
    assert (entity.cubes[4].color.r, entity.cubes[4].color.g) == (1.0, 0.0)  # ego: pink
