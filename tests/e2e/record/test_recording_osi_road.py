"""The road in the OSI trace: lanes, lane boundaries, stationary objects, traffic lights with
their states, and per-sensor SensorData / SensorView with mounting positions, read back with
the ASAM OSI readers (asam-osi-utilities, osi-python) and checked against the SUMO net."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import sumolib
from osi3.osi_lane_pb2 import Lane, LaneBoundary
from osi3.osi_object_pb2 import StationaryObject
from osi3.osi_trafficlight_pb2 import TrafficLight
from osi3trace.osi_trace import OSITrace
from osi_utilities import MultiTraceReader
from shapely.geometry import LineString, Point

from hiyari.bridge.record.osi_road import STATIC_ID_BASE
from hiyari.bridge.record.reader import Recording
from hiyari.bridge.record.recorder import Recorder, RecorderConfig, SensorMount
from hiyari.net.mesh.road_mesh import build_scene_mesh
from hiyari.net.road.geometry import RoadGeometry
from hiyari.net.sumo.build import ExpresswayParams, build_expressway
from hiyari.sensors.frames import Mount
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic import SimConfig, Simulation

GT = "/osi/ground_truth"
B = LaneBoundary.Classification
TOLERANCE_M = 0.05


@pytest.fixture(scope="module")
def recorded(intersection_net, intersection_demand, tmp_path_factory):
    """90 s on the signalised intersection: ground truth with the road and signal states."""
    out = tmp_path_factory.mktemp("osi_road") / "road.mcap"
    states = []
    geometry = RoadGeometry.from_net(intersection_net)
    with (
        Simulation(SimConfig(net=intersection_net, routes=[intersection_demand], seed=3)) as sim,
        Recorder(
            out, {"scenario": "road"}, RecorderConfig(creation_time="2026-01-01T00:00:00Z")
        ) as rec,
    ):
        counts = rec.write_road(geometry, build_scene_mesh(geometry), sim.signal_links())
        for state in sim.run(until=90.0):
            signals = sim.signal_states()
            if round(state.time * 10) % 50 == 0:
                states.append((state.time, signals))
            rec.write_world(state, signals=signals)
    return out, counts, states


def _ground_truths(path: Path) -> list:
    reader = MultiTraceReader()
    assert reader.open(path)
    try:
        reader.set_topics([GT])
        return [r.message for r in reader]
    finally:
        reader.close()


def test_osi_utilities_read_lanes_and_boundaries(recorded, intersection_net, tmp_path):
    path, counts, _ = recorded
    frames = _ground_truths(path)
    assert len(frames) == 900
    assert counts["lanes"] > 20 and counts["lane_boundaries"] > counts["lanes"]
    # static content once, in the first frame (the default) ...
    assert len(frames[0].lane) == counts["lanes"]
    assert len(frames[0].lane_boundary) == counts["lane_boundaries"]
    assert all(len(gt.lane) == 0 and len(gt.traffic_light) > 0 for gt in frames[1:])
    assert len(Recording.open(path).road().lane) == counts["lanes"]
    # ... or in every frame when asked
    every = tmp_path / "every.mcap"
    geometry = RoadGeometry.from_net(intersection_net)
    with (
        Simulation(SimConfig(net=intersection_net)) as sim,
        Recorder(every, {"scenario": "every"}, RecorderConfig(road_every_frame=True)) as rec,
    ):
        rec.write_road(geometry, None, sim.signal_links())
        for state in sim.run(until=1.0):
            rec.write_world(state, signals=sim.signal_states())
    again = _ground_truths(every)
    assert len(again) == 10
    assert all(
        gt.lane == frames[0].lane and gt.lane_boundary == frames[0].lane_boundary for gt in again
    )
    gt = frames[0]
    ids = [x.id.value for x in (*gt.lane, *gt.lane_boundary, *gt.traffic_light)]
    assert len(set(ids)) == len(ids) and min(ids) >= STATIC_ID_BASE
    assert all(m.id.value < STATIC_ID_BASE for m in gt.moving_object)
    boundary_ids = {b.id.value for b in gt.lane_boundary}
    for lane in gt.lane:
        c = lane.classification
        refs = [*c.left_lane_boundary_id, *c.right_lane_boundary_id]
        assert c.left_lane_boundary_id and c.right_lane_boundary_id
        assert {r.value for r in refs} <= boundary_ids


def test_lane_geometry_reconstructed_within_5_cm_of_the_sumo_net(recorded, intersection_net):
    """Centre lines and both borders (so the widths) from the trace alone, against sumolib's
    reading of the net: every lane with a shape, junction lanes and crossings included."""
    gt = Recording.open(recorded[0]).road()
    boundaries = {b.id.value: b for b in gt.lane_boundary}
    by_sumo = {lane.source_reference[0].identifier[0]: lane for lane in gt.lane}
    net = sumolib.net.readNet(
        str(intersection_net), withInternal=True, withPedestrianConnections=True
    )
    checked = 0
    for edge in net.getEdges(withInternal=True):
        if edge.getFunction() == "walkingarea":
            continue
        for sumo_lane in edge.getLanes():
            shape = np.array(sumo_lane.getShape3D())
            if len(shape) < 2 or LineString(shape[:, :2]).length < 0.1:
                continue
            lane = by_sumo[sumo_lane.getID()]
            c = lane.classification
            centre = np.array([[p.x, p.y, p.z] for p in c.centerline])
            assert _hausdorff(centre, shape) < TOLERANCE_M, sumo_lane.getID()
            # each border runs half a lane width from every point of SUMO's centre line
            half = sumo_lane.getWidth() / 2
            for side in (c.left_lane_boundary_id, c.right_lane_boundary_id):
                border = LineString(
                    [(p.position.x, p.position.y) for p in boundaries[side[0].value].boundary_line]
                )
                d = np.array([border.distance(Point(p)) for p in shape[:, :2]])
                assert np.all(np.abs(d - half) < TOLERANCE_M), (sumo_lane.getID(), d, half)
            checked += 1
    assert checked >= 30


def _hausdorff(a: np.ndarray, b: np.ndarray) -> float:
    la, lb = LineString(a[:, :2]), LineString(b[:, :2])
    return max(
        max(lb.distance(Point(p)) for p in a[:, :2]), max(la.distance(Point(p)) for p in b[:, :2])
    )


def test_boundary_types_follow_the_markings(recorded, intersection_net):
    gt = _ground_truths(recorded[0])[0]
    types = Counter(b.classification.type for b in gt.lane_boundary)
    # edge lines of the carriageway, kerbs beside the sidewalks, virtual borders in the junction
    assert types[B.TYPE_SOLID_LINE] > 0 and types[B.TYPE_CURB] > 0 and types[B.TYPE_NO_LINE] > 0
    painted = [b for b in gt.lane_boundary if b.classification.type == B.TYPE_SOLID_LINE]
    assert all(b.classification.color == B.COLOR_WHITE for b in painted)
    assert all(p.width == pytest.approx(0.15) for b in painted for p in b.boundary_line)
    kerbs = [b for b in gt.lane_boundary if b.classification.type == B.TYPE_CURB]
    assert all(p.height == pytest.approx(0.15) for b in kerbs for p in b.boundary_line)
    lane_type = {
        lane.source_reference[0].identifier[0]: (
            lane.classification.type,
            lane.classification.subtype,
        )
        for lane in gt.lane
    }
    geometry = RoadGeometry.from_net(intersection_net)
    for ln in geometry.sidewalks:
        assert lane_type[ln.id] == (
            Lane.Classification.TYPE_NONDRIVING,
            Lane.Classification.SUBTYPE_SIDEWALK,
        )
    for ln in geometry.driving_lanes:
        assert lane_type[ln.id][0] == Lane.Classification.TYPE_DRIVING
    internal = [ln for ln in geometry.lanes.values() if ln.internal and ln.kind == "driving"]
    assert internal and all(
        lane_type[ln.id][0] == Lane.Classification.TYPE_INTERSECTION for ln in internal
    )


def test_dashed_lines_between_lanes_that_may_be_changed(tmp_path):
    """Two lanes per direction: a dashed boundary between them, solid edge lines outside."""
    net = build_expressway(
        tmp_path / "x.net.xml",
        ExpresswayParams(length=600.0, curve_length=0.0, on_ramp=False, off_ramp=False),
    )
    geometry = RoadGeometry.from_net(net)
    mesh = build_scene_mesh(geometry)
    path = tmp_path / "x.mcap"
    with Recorder(path, {"scenario": "x"}) as rec:
        rec.write_road(geometry, mesh)
        from hiyari.traffic import WorldState

        rec.write_world(WorldState.empty(0.0))
    gt = _ground_truths(path)[0]
    boundaries = {b.id.value: b for b in gt.lane_boundary}
    east = {lane.source_reference[0].identifier[0]: lane for lane in gt.lane}
    left_of_0 = east["east_0"].classification.left_lane_boundary_id
    right_of_1 = east["east_1"].classification.right_lane_boundary_id
    assert [b.value for b in left_of_0] == [b.value for b in right_of_1]  # shared
    assert boundaries[left_of_0[0].value].classification.type == B.TYPE_DASHED_LINE
    edge_line = boundaries[east["east_0"].classification.right_lane_boundary_id[0].value]
    assert edge_line.classification.type == B.TYPE_SOLID_LINE
    assert [a.value for a in east["east_0"].classification.left_adjacent_lane_id] == [
        east["east_1"].id.value
    ]
    # guard rails of the scene mesh as barriers: beams 0.3-0.8 m above the road
    rails = [
        s
        for s in gt.stationary_object
        if s.classification.type == StationaryObject.Classification.TYPE_BARRIER
    ]
    assert rails
    for s in rails:
        assert s.base.dimension.height == pytest.approx(0.5, abs=0.05)
        assert len(s.base.base_polygon) >= 4
        xy = np.array([[p.x, p.y] for p in s.base.base_polygon])
        assert np.all(np.abs(xy[:, 0]) <= s.base.dimension.length / 2 + 1e-6)


def test_traffic_lights_carry_sumo_states(recorded):
    path, counts, states = recorded
    assert counts["traffic_lights"] == 1
    frames = {
        round(gt.timestamp.seconds + gt.timestamp.nanos / 1e9, 3): gt for gt in _ground_truths(path)
    }
    colour = {
        "G": TrafficLight.Classification.COLOR_GREEN,
        "g": TrafficLight.Classification.COLOR_GREEN,
        "y": TrafficLight.Classification.COLOR_YELLOW,
        "r": TrafficLight.Classification.COLOR_RED,
    }
    seen = set()
    for time, signals in states:
        gt = frames[round(time, 3)]
        (state,) = signals.values()
        lights = {int(t.source_reference[0].identifier[1]): t for t in gt.traffic_light}
        assert sorted(lights) == sorted(set(range(len(state))) & set(lights))
        for index, light in lights.items():
            assert light.classification.color == colour[state[index]]
            seen.add(state[index])
        icons = Counter(t.classification.icon for t in gt.traffic_light)
        assert icons[TrafficLight.Classification.ICON_PEDESTRIAN] > 0
    assert {"G", "r"} <= seen  # the lights changed during the run


def _objects(time: float, source: str, frame: np.ndarray) -> ObjectList:
    return ObjectList(
        time=time,
        source=source,
        frame_to_world=frame,
        object_id=np.array([1], np.int64),
        cls=np.array([0], np.int8),
        position=np.array([[12.0, -1.0, 0.2]]),
        velocity=np.array([[-3.0, 0.0, 0.0]]),
        size=np.array([[4.5, 1.8, 1.5]]),
        confidence=np.array([0.9]),
        truth=np.array(["car"], dtype=object),
    )


def test_sensor_data_and_views_per_sensor_with_mounting(tmp_path):
    """Each source's SensorData carries the ego and the sensor's mounting position; asking
    the OSI reader for SensorData without a topic gives every source, not just one."""
    from hiyari.bridge.record.osi_convert import vehicle_pose
    from hiyari.sensors.scene.synthetic import actor_world
    from hiyari.traffic import ActorClass

    mounts = {"radar": Mount(x=2.3, z=0.5), "lidar": Mount(x=0.0, z=1.9, pitch_deg=2.0)}
    path = tmp_path / "s.mcap"
    with Recorder(path, {"scenario": "s"}) as rec:
        for name, m in mounts.items():
            rec.add_sensor_config(name, {}, SensorMount(name, m.sensor_to_ego(), 1.0, 0.2))
        for k in range(3):
            t = 0.1 * k
            world = actor_world(
                [
                    dict(id="ego", cls=ActorClass.CAR, x=10.0 + k, y=5.0, z=1.0, heading=0.3),
                    dict(id="car", cls=ActorClass.CAR, x=30.0, y=7.0, z=1.0, heading=0.3),
                ],
                t,
            )
            rec.write_world(world, "ego")
            vehicle = vehicle_pose(10.0 + k, 5.0, 1.0, 0.3)
            for name in ("radar", "lidar"):
                rec.write_objects(_objects(t, name, vehicle @ mounts[name].sensor_to_ego()))
            rec.write_objects(_objects(t, "fusion", vehicle))
    trace = OSITrace(str(path), "SensorData")  # no topic
    try:
        messages = list(trace)
    finally:
        trace.close()
    assert Counter(m.sensor_id.value for m in messages) == {1: 3, 2: 3, 3: 3}
    radar = [m for m in messages if m.sensor_id.value == 1][0]
    mp = radar.mounting_position
    # OSI's vehicle frame: origin at the middle of the rear axle, which for the 4.5 x 1.8 x
    # 1.5 m car is 0.18 x 4.5 = 0.81 m ahead of its rear end (2.25 - 0.81 = 1.44 m behind the
    # centre) and 0.21 x 1.5 = 0.315 m up; the radar 2.3 m ahead of the centre, 0.5 m up
    assert (mp.position.x, mp.position.y, mp.position.z) == pytest.approx((3.74, 0.0, 0.185))
    host = radar.host_vehicle_location
    assert (host.position.x, host.position.y) == pytest.approx((10.0, 5.0))
    assert host.orientation.yaw == pytest.approx(0.3)
    views = OSITrace(str(path), "SensorView", topic="/osi/sensor_view")
    try:
        sv = list(views)
    finally:
        views.close()
    assert len(sv) == 6 and {v.sensor_id.value for v in sv} == {1, 2}
    lidar = [v for v in sv if v.sensor_id.value == 2][0]
    assert lidar.mounting_position.position.x == pytest.approx(1.44)
    assert lidar.mounting_position.position.z == pytest.approx(1.9 - 0.315)
    assert lidar.mounting_position.orientation.pitch == pytest.approx(np.radians(2.0))
    assert lidar.lidar_sensor_view[0].view_configuration.field_of_view_horizontal == 1.0
    assert lidar.host_vehicle_id.value == 1
    # hiyari's reader puts each list back in its own frame
    rec = Recording.open(path)
    back = rec.objects("lidar", 2)
    want = vehicle_pose(12.0, 5.0, 1.0, 0.3) @ mounts["lidar"].sensor_to_ego()
    np.testing.assert_allclose(back.frame_to_world, want, atol=1e-12)
    # and OSI's rule gives the same place: the host's box centre + R bbcenter_to_rear
    # (ground truth of the same time), then the mounting position of the sensor view
    gt = rec.ground_truth(2)
    (ego,) = [m for m in gt.moving_object if m.id.value == gt.host_vehicle_id.value]
    b2r = ego.vehicle_attributes.bbcenter_to_rear
    assert (b2r.x, b2r.y, b2r.z) == pytest.approx((-1.44, 0.0, 0.315 - 0.75))
    c, s = np.cos(ego.base.orientation.yaw), np.sin(ego.base.orientation.yaw)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    p = ego.base.position
    origin = np.array([p.x, p.y, p.z]) + rot @ [b2r.x, b2r.y, b2r.z]
    m = lidar.mounting_position.position
    np.testing.assert_allclose(origin + rot @ [m.x, m.y, m.z], want[:3, 3], atol=1e-12)
    assert rec.object_sources == ["fusion", "lidar", "radar"]
