"""Synthetic sensors recorded with a real SUMO run follow the ground truth."""

from __future__ import annotations

import numpy as np
from recording_data import road_mesh, synthetic_lidar, synthetic_radar

from hiyari.net.mesh.materials import Material
from hiyari.traffic import SimConfig, Simulation


def test_synthetic_sensors_follow_ground_truth(intersection_net, intersection_demand):
    """LiDAR points hit the actors they claim to hit; radar ranges match the geometry."""
    with Simulation(SimConfig(net=intersection_net, routes=[intersection_demand], seed=3)) as sim:
        for _ in sim.run(until=30.0):
            pass
        state = sim.state
    row = int(np.flatnonzero(state.is_vehicle)[0])
    rng = np.random.default_rng(0)
    pc = synthetic_lidar(state, row, rng)
    world = pc.xyz.astype(np.float64) @ pc.sensor_to_world[:3, :3].T + pc.sensor_to_world[:3, 3]
    on = pc.hit >= 0
    assert on.any()
    gap = np.linalg.norm(world[on, :2] - state.xyz[pc.hit[on], :2], axis=1)
    assert np.all(gap <= 0.5 * np.hypot(state.length, state.width)[pc.hit[on]] + 1e-3)
    det = synthetic_radar(state, row, rng)
    assert np.allclose(np.linalg.norm(det.xyz(), axis=1), det.range)
    mesh = road_mesh(intersection_net)
    assert len(mesh.faces) >= 8 and Material.ASPHALT in set(mesh.material.tolist())
