"""Run one concrete catalogue case in closed loop: SUMO + the scenario engine for the
surrounding vehicles + an ego stack (the one under test, or the C&C reference driver).

The ego's own lane change is commanded to SUMO at its time (SUMO's continuous lane change,
``--lanechange.duration`` = lane width / lateral speed); the stack drives its speed.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from hiyari.bridge.loop.closed_loop import run_closed_loop
from hiyari.bridge.loop.engine_run import (
    EgoSetup,
    EngineHooks,
    StackContext,
    StackFactory,
    default_stack,
)
from hiyari.bridge.loop.result import RunResult
from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.studies.catalogue.space.concrete import ConcreteCase, EgoLaneChange, to_scenario
from hiyari.bridge.studies.catalogue.space.layout import LANE_WIDTH
from hiyari.errors import HiyariError
from hiyari.net.road.network import RoadNetwork
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.sumo.build import CatalogueRoadParams, build_catalogue_road, xodr_beside
from hiyari.traffic.simulation import SimConfig, Simulation
from hiyari.traffic.world_state import WorldState

GEOMETRY_ID = {"main line": "main", "merge": "merge", "branch": "branch"}
#: How long (s) SUMO keeps the ego in its new lane after a commanded change.
LANE_HOLD_S = 600.0


@dataclass(frozen=True)
class RunConfig:
    """How the catalogue's concrete cases run. ``stack``: "module:callable" building the ego
    stack from a StackContext (empty: hiyari's default stack with ``perception``)."""

    roads: Path
    perception: str = "perfect"
    stack: str = ""
    step_length: float = 0.1
    aeb_delay: float = 0.2


def road_files(roads: Path, geometry: str, lanes: int) -> tuple[Path, Path]:
    """(xodr, net) of a generated catalogue road in folder ``roads``."""
    net = roads / f"{GEOMETRY_ID[geometry]}-{lanes}.net.xml"
    return xodr_beside(net), net


def prepare_road(roads: Path, geometry: str, lanes: int) -> tuple[Path, Path]:
    """Generate the road once (OpenDRIVE + SUMO net) unless it is there."""
    xodr, net = road_files(roads, geometry, lanes)
    if not (net.is_file() and xodr.is_file()):
        roads.mkdir(parents=True, exist_ok=True)
        build_catalogue_road(net, CatalogueRoadParams(lanes=lanes), GEOMETRY_ID[geometry])
    return xodr, net


@lru_cache(maxsize=8)
def _road(xodr: Path, net: Path) -> tuple[RoadLanes, RoadNetwork]:
    """Parsed road (cached per worker process: every run on a road reuses it)."""
    return RoadLanes.from_files(xodr, net), RoadNetwork(net)


def load_factory(spec: str) -> StackFactory:
    """The user's stack factory named "module:callable"."""
    module, _, name = spec.partition(":")
    try:
        return getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError, ValueError) as exc:
        raise HiyariError(f"--stack: cannot load {spec!r}: {exc}") from None


class CatalogueHooks(EngineHooks):
    """EngineHooks plus the ego's commanded lane change."""

    def __init__(self, engine: ScenarioEngine, sim: Simulation, roads: RoadLanes,
                 lane_change: EgoLaneChange | None) -> None:  # fmt: skip
        super().__init__(engine, sim)
        self.roads = roads
        self.lane_change = lane_change
        self._world: WorldState | None = None

    def after_step(self, sim: Simulation, world: WorldState) -> bool:
        self._world = world
        return super().after_step(sim, world)

    def before_step(self, sim: Simulation, script_time: float) -> None:
        lc, w = self.lane_change, self._world
        if lc is None or w is None or self.ego_id not in w.ids:
            return
        if self.engine.now + 1e-9 < lc.time:
            return
        x = float(w.xyz[w.index(self.ego_id), 0])  # the catalogue road runs along +x from 0
        lane = self.roads.sumo_lane(lc.road, lc.lane, x)
        if lane is not None:
            sim.change_lane(self.ego_id, lane.index, LANE_HOLD_S)
            self.lane_change = None


def run_case(case: ConcreteCase, config: RunConfig, factory: StackFactory | None = None,
             record: Path | None = None) -> RunResult:  # fmt: skip
    """Run ``case`` once with the stack ``factory`` builds (None: the configured stack).
    ``record``: write the MCAP recording to this file."""
    c = case.cell.combination
    xodr, net = prepare_road(config.roads, c.geometry.value, case.cell.lanes)
    roads, network = _road(xodr, net)
    lc = case.ego_lane_change()
    extra: tuple[str, ...] = ()
    if lc is not None:
        extra = ("--lanechange.duration", repr(LANE_WIDTH / lc.lateral_speed))
    setup = EgoSetup(
        perception=config.perception,
        step_length=config.step_length,
        seed=case.seed,
        aeb_delay=config.aeb_delay,
        max_duration=case.ranges.duration + 1.0,
    )
    scenario = to_scenario(case)
    if factory is None:
        factory = load_factory(config.stack) if config.stack else default_stack
    cfg = SimConfig(net=net, step_length=config.step_length, seed=case.seed, generated=(net,),
                    extra_args=extra)  # fmt: skip
    with Simulation(cfg) as sim:
        engine = ScenarioEngine(scenario, roads, config.step_length)
        hooks = CatalogueHooks(engine, sim, roads, lc)
        ctx = StackContext(network, setup, "ego", case.params["ego_speed"], scenario)
        stack = factory(ctx)
        on_step, recorder = None, None
        if record is not None:
            on_step, recorder = _recorder(record, scenario, setup, stack, network, hooks)
        try:
            result = run_closed_loop(sim, stack, hooks, setup.max_duration, label=case.run_id,
                                     on_step=on_step)  # fmt: skip
        except BaseException:
            # an interrupted or failed run keeps the .part name: never taken for the run
            if recorder is not None:
                recorder.close(complete=False)
            raise
        if recorder is not None:
            recorder.close()
    return result


def _recorder(path: Path, scenario: object, setup: EgoSetup, stack: object,
              network: RoadNetwork, hooks: CatalogueHooks) -> tuple:  # fmt: skip
    from hiyari.bridge.loop.engine_run import scenario_doc
    from hiyari.bridge.loop.recording import StepRecorder, open_recorder

    path.parent.mkdir(parents=True, exist_ok=True)
    meta = {**scenario_doc(scenario, setup), "scenario": scenario.name}
    recorder = open_recorder(path, meta, stack, network, [])
    return StepRecorder(recorder, stack, hooks.ego_id, None), recorder
