"""What runs on the same road can share inside one process: the road file and its RoadNetwork,
the static Embree scene and the sensor rig, each built once and reused.

A ``WarmCache`` belongs to one process (a pool worker keeps one across its runs). Reuse never
changes results: the road is written by the same deterministic builder with the same
parameters, the scene's static part is immutable (actors are replaced at every update) and the
sensors' only state is a cache keyed by its input (soiling masks). Per-run state (noise
streams, trackers, the planner, SUMO itself) is still made fresh for every run.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable, Hashable, Sequence
from pathlib import Path
from typing import Any

from hiyari.net.mesh.road_mesh import network_scene_mesh
from hiyari.net.road.network import RoadNetwork
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.road.sumo_roads import sumo_road_lanes
from hiyari.sensors.rig import SensorRig
from hiyari.sensors.scene.ray_scene import RayScene


class WarmCache:
    """Roads, ray-cast scenes and rigs built once per process (see module docstring).

    A cache inherited through ``fork`` is left alone (its scene's cast threads did not come
    along): :meth:`for_this_process` gives a fresh one in the child.
    """

    def __init__(self) -> None:
        self.pid = os.getpid()
        self._folder: Path | None = None
        self._roads: dict[tuple[str, Hashable], RoadNetwork] = {}
        self._lanes: dict[Path, RoadLanes] = {}
        self._scenes: dict[tuple[Path, bool, int], RayScene] = {}
        self._rigs: dict[tuple[str, ...], SensorRig] = {}

    def road(self, name: str, build: Callable[[Path, Any], Path], params: Hashable) -> RoadNetwork:
        """The RoadNetwork of ``build(folder / name, params)``, built on the first call."""
        key = (name, params)
        if key not in self._roads:
            if self._folder is None:
                self._folder = Path(tempfile.mkdtemp(prefix="hiyari-warm-"))
            folder = self._folder / str(len(self._roads))
            folder.mkdir()
            self._roads[key] = RoadNetwork(build(folder / name, params))
        return self._roads[key]

    def road_lanes(self, network: RoadNetwork) -> RoadLanes:
        """The road / lane / s frame of a generated net (its edges as roads), built once."""
        if network.path not in self._lanes:
            self._lanes[network.path] = sumo_road_lanes(network)
        return self._lanes[network.path]

    def scene(self, network: RoadNetwork, buildings: bool, workers: int) -> RayScene:
        """The RayScene of ``network``'s static mesh (``workers`` cast threads)."""
        key = (network.path, buildings, workers)
        if key not in self._scenes:
            mesh = network_scene_mesh(network, buildings=buildings)
            self._scenes[key] = RayScene(mesh, workers=workers)
        return self._scenes[key]

    def rig(self, sensors: Sequence[str]) -> SensorRig:
        """The default rig with only the sensors named in ``sensors``."""
        key = tuple(sensors)
        if key not in self._rigs:
            rig = SensorRig.default()
            rig.sensors = [s for s in rig.sensors if s.name in key]
            self._rigs[key] = rig
        return self._rigs[key]

    def clear(self) -> None:
        """Drop everything and remove the road files."""
        self._roads.clear()
        self._lanes.clear()
        self._scenes.clear()
        self._rigs.clear()
        if self._folder is not None:
            shutil.rmtree(self._folder, ignore_errors=True)
            self._folder = None


class ProcessCache:
    """Holder of this process's WarmCache: the one place a worker keeps warm state."""

    def __init__(self) -> None:
        self._cache: WarmCache | None = None

    def for_this_process(self) -> WarmCache:
        """This process's cache (a new one after a fork)."""
        if self._cache is None or self._cache.pid != os.getpid():
            self._cache = WarmCache()
        return self._cache

    def clear(self) -> None:
        """Drop this process's cache (not a parent's inherited one: its files are the
        parent's)."""
        if self._cache is not None and self._cache.pid == os.getpid():
            self._cache.clear()
        self._cache = None
