"""One concrete catalogue case as a run (:func:`case_spec`, run by
hiyari.bridge.loop.execute): the scenario engine moves the surrounding vehicles, an ego stack
(the one under test, or the C&C reference driver) drives the ego.

The ego's own lane change is commanded to SUMO at its time (SUMO's continuous lane change,
``--lanechange.duration`` = lane width / lateral speed); the stack drives its speed.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache, partial
from pathlib import Path

from hiyari.bridge.loop.hooks import EngineHooks
from hiyari.bridge.loop.spec import EgoSetup, Road, RunSpec, StackFactory, load_stack, model_spec
from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.model.scoring import Scoring
from hiyari.bridge.studies.catalogue.space.concrete import ConcreteCase, EgoLaneChange, to_scenario
from hiyari.bridge.studies.catalogue.space.layout import LANE_WIDTH
from hiyari.net.road.network import RoadNetwork
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.sumo.build import CatalogueRoadParams, build_catalogue_road, xodr_beside
from hiyari.traffic.simulation import Simulation
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


class CatalogueHooks(EngineHooks):
    """EngineHooks plus the ego's commanded lane change."""

    def __init__(self, engine: ScenarioEngine, sim: Simulation, scoring: Scoring,
                 roads: RoadLanes, lane_change: EgoLaneChange | None) -> None:  # fmt: skip
        super().__init__(engine, sim, scoring)
        self.roads = roads
        self.lane_change = lane_change
        self._commanded = False  # the case's own lane change is under way or done
        self._world: WorldState | None = None

    def ego_lane_scripted(self) -> bool:
        return self._commanded or super().ego_lane_scripted()

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
            self._commanded = True


def case_spec(case: ConcreteCase, config: RunConfig, stack: StackFactory | None = None) -> RunSpec:
    """The run of ``case`` on its generated road (made once in ``config.roads``) with the
    stack ``stack`` builds (None: the configured stack)."""
    c = case.cell.combination
    xodr, net = prepare_road(config.roads, c.geometry.value, case.cell.lanes)
    roads, network = _road(xodr, net)
    lc = case.ego_lane_change()
    extra: tuple[str, ...] = ()
    if lc is not None:
        extra = ("--lanechange.duration", repr(LANE_WIDTH / lc.lateral_speed))
    if stack is None and config.stack:
        stack = load_stack(config.stack, "--stack")
    setup = EgoSetup(
        perception=config.perception,
        step_length=config.step_length,
        seed=case.seed,
        aeb_delay=config.aeb_delay,
        max_duration=case.ranges.duration + 1.0,
        stack=stack,
    )
    spec = model_spec(to_scenario(case), setup)
    return replace(
        spec,
        road=Road(xodr, net, network, roads),
        label=case.run_id,
        hooks=partial(CatalogueHooks, roads=roads, lane_change=lc),
        sumo_args=extra,
    )
