"""Run a scenario-model ``Scenario`` in closed loop: the ScenarioEngine drives every scripted
actor from the storyboard, the ego stack (hiyari's or the caller's) drives the ego unless the
file gives the ego to the storyboard; ground-truth verdicts (collision, minimum TTC, minimum
gap) come from hiyari.risk.metrics.ground_truth through the shared closed loop, so results,
recordings and replays are those of every other run.

Use::

    sc = read_scenario("cut_in.xosc")
    result = run_scenario(sc, RunOptions(out_dir=Path("out/cut_in"), record=True))
"""

from __future__ import annotations

import contextlib
import math
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from hiyari.bridge.loop.closed_loop import (
    Decided,
    OnStep,
    ScenarioHooks,
    run_closed_loop,
)
from hiyari.bridge.loop.result import RunResult
from hiyari.bridge.loop.run import RunOptions, chain, run_folder, write_result
from hiyari.bridge.loop.scenario_environment import disturbance_from, grip
from hiyari.bridge.loop.stack.aeb import ACCConfig, AEBConfig, AEBPlanner
from hiyari.bridge.loop.stack.fusion import KalmanFusion
from hiyari.bridge.loop.stack.interfaces import EgoStack
from hiyari.bridge.loop.stack.perception_sensors import SensorPerception
from hiyari.bridge.loop.stack.perception_truth import NoPerception, PerfectPerception
from hiyari.bridge.openscenario.engine import ScenarioEngine, StepReport
from hiyari.bridge.openscenario.model.global_actions import Environment as ScenarioEnvironment
from hiyari.bridge.openscenario.model.scoring import Scoring
from hiyari.bridge.openscenario.model.storyboard import Scenario
from hiyari.bridge.openscenario.presets.toml_file import PERCEPTION_MODES, SENSOR_NAMES
from hiyari.errors import HiyariError
from hiyari.kinematics import Pose, bumper_gap, unrotate
from hiyari.net.road.network import RoadNetwork
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.sensors.environment.presets import disturbance_preset
from hiyari.traffic.simulation import SimConfig, Simulation
from hiyari.traffic.world_state import WorldState

#: The environment name under which the sensors see the scenario's own EnvironmentAction.
SCENARIO_ENVIRONMENT = "scenario"


@dataclass(frozen=True)
class EgoSetup:
    """The ego stack and the run's clock for a model scenario.

    ``perception``: perfect | sensors | none; ``sensors`` used with "sensors"; ``environment``
    a disturbance preset; ``aeb_delay`` s; ``set_speed`` the ACC set speed, m/s (None: the
    ego's speed after the Init actions); ``step_length`` s; ``seed`` SUMO's and the sensors'
    seed; ``max_duration`` s of scenario time after which the run ends if the stop trigger
    has not fired."""

    perception: str = "perfect"
    sensors: tuple[str, ...] = SENSOR_NAMES
    environment: str = "clear"
    aeb_delay: float = 0.2
    set_speed: float | None = None
    step_length: float = 0.05
    seed: int = 1
    max_duration: float = 600.0

    def __post_init__(self) -> None:
        if self.perception not in PERCEPTION_MODES:
            raise HiyariError(
                f"perception {self.perception!r} is not one of {', '.join(PERCEPTION_MODES)}"
            )
        unknown = set(self.sensors) - set(SENSOR_NAMES)
        if unknown:
            raise HiyariError(f"unknown sensor(s) {sorted(unknown)} (known: {SENSOR_NAMES})")
        if not 0.001 <= self.step_length <= 0.5:
            raise HiyariError(f"step_length must be within 0.001..0.5 s, got {self.step_length}")
        if not self.max_duration > 0:
            raise HiyariError(f"max_duration must be positive, got {self.max_duration}")


@dataclass(frozen=True)
class StackContext:
    """What a stack factory gets: the run's road, setup, the ego's id and its ACC set speed
    (m/s), the scenario, and the environment its Init actions set (None: none)."""

    network: RoadNetwork
    setup: EgoSetup
    ego_id: str
    set_speed: float
    scenario: Scenario
    environment: ScenarioEnvironment | None = None


#: Builds the ego stack for one run (called once, after the Init actions are applied).
StackFactory = Callable[[StackContext], EgoStack]


def default_stack(ctx: StackContext) -> EgoStack:
    """hiyari's stack: perfect / no / sensor perception, Kalman fusion, ACC + AEB. With the
    environment "scenario" the sensors see the scenario's EnvironmentAction (clear when it
    has none); the road's friction scales the decelerations the planner commands."""
    s = ctx.setup
    if s.perception == "perfect":
        perception = PerfectPerception()
    elif s.perception == "none":
        perception = NoPerception()
    else:
        preset = None
        if s.environment == SCENARIO_ENVIRONMENT:
            preset = disturbance_preset("clear")
            if ctx.environment is not None:
                preset = disturbance_from(ctx.environment)
        perception = SensorPerception.default_rig(
            ctx.network, s.sensors, s.environment, s.step_length, s.seed, ego_id=ctx.ego_id,
            preset=preset,
        )  # fmt: skip
    mu = min(1.0, grip(ctx.environment))
    aeb = AEBConfig(actuation_delay=s.aeb_delay)
    aeb = replace(aeb, partial_decel_g=aeb.partial_decel_g * mu, full_decel_g=aeb.full_decel_g * mu)
    acc = ACCConfig(set_speed=ctx.set_speed)
    planner = AEBPlanner(replace(acc, max_decel=acc.max_decel * mu), aeb)
    return EgoStack(perception, KalmanFusion(), planner)


class EngineHooks(ScenarioHooks):
    """The closed loop's view of a ScenarioEngine: it steps the storyboard on every new state,
    ends the run at the stop trigger, and says whether the stack drives the ego. ``scoring``:
    the scored gap is to its target, else to the nearest actor ahead in the ego's corridor
    (bumper to bumper); its conflict point and settle rule apply."""

    def __init__(self, engine: ScenarioEngine, sim: Simulation, scoring: Scoring | None = None):
        self.engine = engine
        self.scoring = scoring or Scoring()
        self.ego_id = engine.ego or ""
        self.target_id = self.scoring.target
        self.conflict_point = self.scoring.conflict_point
        self.report: StepReport = engine.start(sim)
        self.ego_requests: list[tuple[float, str]] = []
        self._stopped_at = math.nan

    def after_step(self, sim: Simulation, world: WorldState) -> bool:
        self.report = self.engine.step(sim, world)
        self.ego_requests.extend((self.report.time, n) for n in self.report.ego_requests)
        return self.report.finished

    def stack_drives_ego(self) -> bool:
        return not self.report.ego_storyboard_driven

    def drive_ego(self, sim: Simulation, ego_id: str, speed: float) -> None:
        self.engine.drive_ego(sim, speed)

    def sensed(self, world: WorldState) -> WorldState:
        hidden = self.engine.hidden_from_sensors()
        if not hidden:
            return world
        return world.select(~np.isin(world.ids, hidden))

    def done(self, world: WorldState, ego: Pose, script_time: float) -> bool:
        """True ``scoring.settle_after_stop`` s after the ego first stood still."""
        now, sc = self.report.time, self.scoring
        if ego.speed < 0.05 and now > sc.settle_from and not np.isfinite(self._stopped_at):
            self._stopped_at = now
        return now - self._stopped_at >= sc.settle_after_stop

    def gap_target(self, world: WorldState, row: int) -> int:
        if self.target_id:
            return super().gap_target(world, row)
        xy = world.xyz[:, :2]
        rel = unrotate(xy - xy[row], float(world.heading[row]))
        along, across = bumper_gap(
            rel, world.length[row], world.width[row], world.length, world.width
        )
        ahead = (across < 0) & (along > -world.length)
        ahead[row] = False
        if not ahead.any():
            return -1
        return int(np.flatnonzero(ahead)[np.argmin(along[ahead])])


def import_road(scenario: Scenario, workdir: Path) -> Path:
    """The SUMO net of the scenario's OpenDRIVE road, imported into ``workdir``."""
    from hiyari.net.sumo.opendrive import import_opendrive

    xodr = scenario.road_network
    if xodr is None:
        raise HiyariError(f"{scenario.source or scenario.name}: the scenario names no road")
    workdir.mkdir(parents=True, exist_ok=True)
    return import_opendrive(xodr, workdir / f"{Path(xodr).stem}.net.xml")


def run_scenario(
    scenario: Scenario,
    options: RunOptions | None = None,
    setup: EgoSetup | None = None,
    stack_factory: StackFactory | None = None,
    net: Path | None = None,
    on_step: OnStep | None = None,
) -> RunResult:
    """Run ``scenario`` once in closed loop in this process (one libsumo simulation at a time).

    ``net``: the SUMO net imported from ``scenario.road_network`` (None: imported here, into
    ``options.out_dir / "roads"`` or a temporary folder). ``stack_factory`` builds the ego
    stack (None: :func:`default_stack`). Ends at the stop trigger, a collision of the ego,
    the ego leaving the network or ``setup.max_duration``. With ``options.out_dir``:
    result.json, timeseries.csv / .png, and run.mcap when ``options.record``; a run that fails
    or is interrupted leaves no output under a final name (bridge.loop.run.run_folder).
    """
    options = options or RunOptions()
    setup = setup or EgoSetup()
    doc = scenario_doc(scenario, setup)
    with run_folder(options.out_dir), tempfile.TemporaryDirectory(prefix="hiyari-run-") as tmp:
        work = options.out_dir / "roads" if options.out_dir else Path(tmp)
        prepared = prepared_scenario(scenario, setup, work, net, stack_factory)
        with prepared as (sim, hooks, stack, network):
            meta = {**doc, "scenario": scenario.name}
            result = drive(
                sim, stack, hooks, scenario.name, setup.max_duration, options, network, meta,
                on_step,
            )  # fmt: skip
        if options.out_dir is not None:
            write_result(result, doc, options.out_dir, plot=options.plot)
    return result


@contextlib.contextmanager
def prepared_scenario(
    scenario: Scenario,
    setup: EgoSetup,
    work: Path,
    net: Path | None = None,
    stack_factory: StackFactory | None = None,
) -> Iterator[tuple[Simulation, EngineHooks, EgoStack, RoadNetwork]]:
    """Everything a run of ``scenario`` does before its first step: the road imported into
    ``work`` (unless ``net`` is given), SUMO started, the Init actions applied and the
    storyboard's statically decided actions checked (ScenarioEngine.start), the ego stack
    built; SUMO is closed on leaving."""
    if scenario.ego is None:
        raise HiyariError(f"{scenario.source or scenario.name}: the scenario has no ego")
    net = net or import_road(scenario, work)
    roads = RoadLanes.from_files(scenario.road_network, net)
    network = RoadNetwork(net)
    cfg = SimConfig(net=net, step_length=setup.step_length, seed=setup.seed, generated=(net,))
    with Simulation(cfg) as sim:
        engine = ScenarioEngine(scenario, roads, setup.step_length)
        hooks = EngineHooks(engine, sim)
        set_speed = setup.set_speed
        if set_speed is None:  # a backing ego's speed is negative: the stack holds |v|
            set_speed = abs(engine.actors[scenario.ego].v)
        ctx = StackContext(network, setup, scenario.ego, set_speed, scenario, engine.environment)
        yield sim, hooks, (stack_factory or default_stack)(ctx), network


def check_scenario(
    scenario: Scenario,
    setup: EgoSetup | None = None,
    net: Path | None = None,
    stack_factory: StackFactory | None = None,
) -> None:
    """Every check a run of ``scenario`` makes before its first step
    (:func:`prepared_scenario`), in a temporary folder: nothing is written, nothing is run."""
    with tempfile.TemporaryDirectory(prefix="hiyari-run-") as tmp:
        with prepared_scenario(scenario, setup or EgoSetup(), Path(tmp), net, stack_factory):
            pass


def drive(
    sim: Simulation,
    stack: EgoStack,
    hooks: EngineHooks,
    label: str,
    duration: float,
    options: RunOptions,
    network: RoadNetwork,
    meta: dict,
    on_step: OnStep | None = None,
    decided: Decided | None = None,
) -> RunResult:
    """The closed loop of every engine run (presets and OpenSCENARIO files alike) for up to
    ``duration`` s, with the recording (``meta`` its metadata) when ``options.record``."""
    recorder = None
    if options.record:
        from hiyari.bridge.loop.recording import StepRecorder, open_recorder

        links = sim.signal_links()
        recorder = open_recorder(
            options.out_dir / "run.mcap", meta, stack, network, links, options.recorder
        )
        if isinstance(stack.perception, SensorPerception):
            stack.perception.render_every = options.camera_image_every
        signals = sim.signal_states if links else None
        on_step = chain(StepRecorder(recorder, stack, hooks.ego_id, signals), on_step)
    try:
        result = run_closed_loop(
            sim,
            stack,
            hooks,
            duration,
            label=label,
            on_step=on_step,
            progress=options.progress,
            decided=decided,
            open_ended=bool(hooks.engine.scenario.storyboard.stop_trigger),
        )
    except BaseException:
        if recorder is not None:
            recorder.close(complete=False)
        raise
    if recorder is not None:
        recorder.close()
    return result


def scenario_doc(scenario: Scenario, setup: EgoSetup) -> dict:
    """The scenario and ego setup as result.json / recording metadata record them."""
    params = {
        k: v for k, v in scenario.parameters.items() if isinstance(v, int | float | str | bool)
    }
    return {
        "type": "openscenario",
        "name": scenario.name,
        "source": str(scenario.source) if scenario.source else "",
        "road": str(scenario.road_network) if scenario.road_network else "",
        "ego": scenario.ego,
        "seed": setup.seed,
        "params": params,
        **{k: v for k, v in asdict(setup).items() if k != "seed"},
    }
