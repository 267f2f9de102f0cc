"""Record a traffic-only run: every WorldState and contact of a Simulation into one MCAP."""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from hiyari.bridge.record.recorder import Recorder, RecorderConfig
from hiyari.errors import HiyariError
from hiyari.net.mesh.scene_mesh import SceneMesh
from hiyari.net.road.geometry import RoadGeometry
from hiyari.traffic.simulation import SimConfig, Simulation


@dataclass(frozen=True)
class RecordedRun:
    """Where a recorded run went and what it cost. Times in seconds."""

    path: Path
    frames: int
    sim_seconds: float
    wall_seconds: float
    size_bytes: int


def record_simulation(
    sim: Simulation,
    recorder: Recorder,
    until: float,
    ego_id: str | None = None,
    environment: Any = None,
    progress: bool = False,
) -> int:
    """Step ``sim`` up to ``until`` (s), writing each WorldState and its contacts.

    ``ego_id`` is marked as the host vehicle while it is in the network; the states of the
    recorded road's traffic lights go with every step. Returns the number of steps written.
    """
    lights = recorder.signal_ids
    n_steps = max(int(round((until - sim.time) / sim.config.step_length)), 0)
    steps = 0
    with tqdm(total=n_steps, unit="step", desc="record", disable=not progress) as bar:
        for state in sim.run(until=until):
            ego = ego_id if ego_id is not None and np.any(state.ids == ego_id) else None
            signals = sim.signal_states(lights) if lights else None
            recorder.write_world(state, ego, environment, sim.collisions, signals)
            steps += 1
            bar.update(1)
    return steps


def record_traffic(
    config: SimConfig,
    duration: float,
    out: str | Path,
    metadata: Mapping[str, Any] | None = None,
    mesh: SceneMesh | None = None,
    recorder_config: RecorderConfig | None = None,
    progress: bool = True,
) -> RecordedRun:
    """Run ``config`` for ``duration`` simulated seconds and record it to ``out`` (.mcap),
    with the road of its net (lanes, boundaries, traffic lights; stationary objects from
    ``mesh``) in the OSI ground truth."""
    if duration <= 0:
        raise HiyariError(f"duration must be positive, got {duration} s")
    meta = {"scenario": "traffic", "seed": config.seed, "step_length_s": config.step_length}
    meta.update(metadata or {})
    t0 = time.perf_counter()
    with Simulation(config) as sim, Recorder(out, meta, recorder_config) as rec:
        if mesh is not None:
            rec.write_static_mesh(mesh, sim.time)
        if config.net is not None:
            rec.write_road(RoadGeometry.from_net(config.net), mesh, sim.signal_links())
        start = sim.time
        frames = record_simulation(sim, rec, start + duration, progress=progress)
        sim_seconds = sim.time - start
    wall = time.perf_counter() - t0
    path = Path(out)
    return RecordedRun(path, frames, sim_seconds, wall, path.stat().st_size)
