"""Run one concrete scenario end to end: road, SUMO, ego stack, metrics, files, plot."""

from __future__ import annotations

import contextlib
import importlib
import json
import shutil
import tempfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from hiyari.atomic import atomic_path
from hiyari.bridge.loop.closed_loop import OnStep
from hiyari.bridge.loop.decided import DecidedEnd
from hiyari.bridge.loop.result import RunResult
from hiyari.bridge.loop.stack.aeb import ACCConfig, AEBConfig, AEBPlanner
from hiyari.bridge.loop.stack.fusion import KalmanFusion
from hiyari.bridge.loop.stack.interfaces import EgoStack
from hiyari.bridge.loop.stack.perception_sensors import SensorPerception
from hiyari.bridge.loop.stack.perception_truth import NoPerception, PerfectPerception
from hiyari.bridge.loop.warm import WarmCache
from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.presets.scenarios import PresetRun, World, build_scenario
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.bridge.record.format import PART_SUFFIX
from hiyari.errors import HiyariError, WriteFailed
from hiyari.net.road.network import RoadNetwork
from hiyari.sensors.environment.presets import disturbance_preset
from hiyari.traffic.simulation import SimConfig, Simulation
from hiyari.units import kmh_to_mps

if TYPE_CHECKING:
    from hiyari.bridge.loop.engine_run import EngineHooks
    from hiyari.bridge.record.recorder import RecorderConfig

#: Draws a finished run's figure into a PNG file and returns its path.
PlotRun = Callable[[RunResult, Path], Path]

#: Threads each run's static ray casts are split over (same hits for any number).
CAST_WORKERS = 2


@dataclass(frozen=True)
class RunOptions:
    """How to run: write files to ``out_dir`` (None: results only), show a progress bar."""

    out_dir: Path | None = None
    progress: bool = False
    #: draws the run's time series into the given PNG path (None: no figure); the studies' report
    #: wing has one (hiyari.bridge.studies.report.timeseries.plot_timeseries)
    plot: PlotRun | None = None
    record: bool = False  # write out_dir/run.mcap (needs out_dir)
    camera_image_every: int = 10  # when recording: render every Nth camera frame (0: none)
    recorder: RecorderConfig | None = None  # when recording: how (None: the defaults)
    #: end once the rest of the run cannot change its judged values (bridge.scenario.decided)
    end_when_decided: bool = False

    def __post_init__(self) -> None:
        if self.record and self.out_dir is None:
            raise HiyariError("recording needs an output folder")


def build_stack(
    cs: ConcreteScenario, net: Path | RoadNetwork, warm: WarmCache | None = None
) -> EgoStack:
    """The default ego stack for a scenario on ``net`` (a .net.xml, or the run's RoadNetwork),
    or the user's class named in ``cs.stack`` (called as ``cls(cs, net_file)``); sensors cast
    into ``warm``'s scene of the road when given (built once per process)."""
    network = net if isinstance(net, RoadNetwork) else RoadNetwork(net)
    if cs.stack:
        module, _, name = cs.stack.partition(":")
        try:
            cls = getattr(importlib.import_module(module), name)
        except (ImportError, AttributeError) as exc:
            raise HiyariError(f"ego.stack: cannot load {cs.stack!r}: {exc}") from None
        return cls(cs, network.path)
    if cs.perception == "perfect":
        perception = PerfectPerception()
    elif cs.perception == "none":
        perception = NoPerception()
    elif warm is not None:
        scene = warm.scene(network, buildings=False, workers=CAST_WORKERS)
        preset = disturbance_preset(cs.environment)
        rig = warm.rig(cs.sensors)
        perception = SensorPerception(scene, rig, preset, "ego", cs.step_length, cs.seed)
    else:
        perception = SensorPerception.default_rig(
            network, cs.sensors, cs.environment, cs.step_length, cs.seed, workers=CAST_WORKERS
        )
    set_speed = kmh_to_mps(cs.params.get("ve0_kmh", 40.0))
    planner = AEBPlanner(ACCConfig(set_speed=set_speed), AEBConfig(actuation_delay=cs.aeb_delay))
    return EgoStack(perception, KalmanFusion(), planner)


def run_concrete(
    cs: ConcreteScenario,
    options: RunOptions | None = None,
    on_step: OnStep | None = None,
    warm: WarmCache | None = None,
    world: World | None = None,
) -> RunResult:
    """Run one concrete scenario in this process (one libsumo simulation at a time): its
    type's preset of the scenario model, run by the ScenarioEngine in the closed loop every
    scenario runs in (bridge.scenario.engine_run).

    ``warm``: take the road, its ray-cast scene and the sensor rig from this process's cache
    (built by the first run on that road) instead of building them; same results.
    ``world``: a city run's map or SUMO scenario (None: the generated city). A run that
    fails or is interrupted leaves no output under a final name (see :func:`run_folder`).
    """
    # engine_run builds on this module (RunOptions, write_result): imported here
    from hiyari.bridge.loop.engine_run import drive

    options = options or RunOptions()
    with run_folder(options.out_dir), tempfile.TemporaryDirectory(prefix="hiyari-run-") as tmp:
        work = options.out_dir / "roads" if options.out_dir else Path(tmp)
        with prepared_concrete(cs, work, warm, world) as (preset, sim, hooks, stack):
            decided = None
            if options.end_when_decided:
                decided = decided_end(
                    hooks.engine, preset.routes, stack, cs.step_length, preset.scoring.target
                )
            result = drive(
                sim, stack, hooks, cs.label(), cs.duration, options, preset.network,
                concrete_metadata(cs), on_step, decided,
            )  # fmt: skip
        if options.out_dir is not None:
            write_result(result, cs, options.out_dir, plot=options.plot)
    return result


@contextlib.contextmanager
def prepared_concrete(
    cs: ConcreteScenario, work: Path, warm: WarmCache | None = None, world: World | None = None
) -> Iterator[tuple[PresetRun, Simulation, EngineHooks, EgoStack]]:
    """Everything a run of ``cs`` does before its first step: the preset's road built in
    ``work``, the ego stack, SUMO started and warmed up, the Init actions applied and the
    storyboard's statically decided actions checked (ScenarioEngine.start); SUMO is closed
    on leaving."""
    from hiyari.bridge.loop.engine_run import EngineHooks

    preset = build_scenario(cs, work, roads=warm, world=world)
    network = preset.network
    stack = build_stack(cs, network, warm)
    net = network.path
    if preset.sumo is not None:  # the user's scenario as SUMO runs it, at the run's step
        cfg = SimConfig.from_sumocfg(preset.sumo.config, cs.step_length, cs.seed)
    else:
        cfg = SimConfig(
            net=net,
            routes=preset.routes,
            step_length=cs.step_length,
            seed=cs.seed,
            generated=(net, *preset.routes) if world is None else preset.routes,
        )
    with Simulation(cfg) as sim:
        sim.fast_forward(sim.time + preset.warmup)
        engine = ScenarioEngine(preset.scenario, preset.roads, cs.step_length)
        yield preset, sim, EngineHooks(engine, sim, preset.scoring), stack


def check_concrete(cs: ConcreteScenario, world: World | None = None) -> None:
    """Every check a run of ``cs`` makes before its first step (:func:`prepared_concrete`),
    in a temporary folder: nothing is written, nothing is run."""
    with tempfile.TemporaryDirectory(prefix="hiyari-run-") as tmp:
        with prepared_concrete(cs, Path(tmp), world=world):
            pass


@contextlib.contextmanager
def run_folder(out_dir: Path | None) -> Iterator[None]:
    """Around one run writing into ``out_dir``: when the run fails or is interrupted, remove
    the road folder it made there (``roads/``); when it fails (an error, not an interrupt),
    also the recording's ``run.mcap.part``, and ``out_dir`` when the run made it and nothing
    else is in it. An interrupted run, or one stopped by a full disk, keeps ``run.mcap.part``:
    readable up to the interrupt (``hiyari replay --recover``) and never taken for a finished
    recording."""
    if out_dir is None:
        yield
        return
    made_out, made_roads = not out_dir.exists(), not (out_dir / "roads").exists()
    try:
        yield
    except BaseException as exc:
        if made_roads:
            shutil.rmtree(out_dir / "roads", ignore_errors=True)
        if isinstance(exc, Exception) and not isinstance(exc, WriteFailed):
            (out_dir / f"run.mcap{PART_SUFFIX}").unlink(missing_ok=True)
            if made_out and out_dir.is_dir() and not any(out_dir.iterdir()):
                out_dir.rmdir()
        raise


def decided_end(
    engine: ScenarioEngine, routes: Sequence[Path], stack: EgoStack, step: float, target: str
) -> DecidedEnd | None:
    """The decided-end test of a run of vehicles on an empty road (no SUMO demand
    ``routes``) with the ego driven by the default planner (None for anything else);
    ``target``: the actor whose gap is scored."""
    if routes or not isinstance(stack.planner, AEBPlanner):
        return None
    return DecidedEnd.of(engine, stack.planner.acc, step, target)


def chain(first: OnStep, second: OnStep | None) -> OnStep:
    """Call ``first`` and then ``second`` (when given) with the same arguments."""
    if second is None:
        return first

    def both(*args: object) -> None:
        first(*args)
        second(*args)

    return both


def concrete_metadata(cs: ConcreteScenario) -> dict:
    """A TOML concrete scenario as result.json and the recording's metadata record it."""
    return {
        "scenario": cs.label(),
        "scenario_type": cs.type,
        "seed": cs.seed,
        "params": cs.params,
        "perception": cs.perception,
        "sensors": list(cs.sensors),
        "environment": cs.environment,
        "aeb_delay_s": cs.aeb_delay,
        "step_length_s": cs.step_length,
    }


def write_result(
    result: RunResult, scenario: ConcreteScenario | dict, out_dir: Path, plot: PlotRun | None = None
) -> None:
    """result.json (summary + parameters), timeseries.csv and, with ``plot``, timeseries.png in
    ``out_dir``.
    ``scenario``: the TOML concrete scenario, or the scenario section as a dict."""
    out_dir.mkdir(parents=True, exist_ok=True)
    if isinstance(scenario, ConcreteScenario):
        cs = scenario
        scenario = {
            "type": cs.type,
            "name": cs.name,
            "index": cs.index,
            "seed": cs.seed,
            "params": cs.params,
            "perception": cs.perception,
            "sensors": list(cs.sensors),
            "environment": cs.environment,
            "aeb_delay_s": cs.aeb_delay,
        }
    doc = {"scenario": scenario, "result": result.as_dict()}
    with atomic_path(out_dir / "result.json") as tmp:
        tmp.write_text(json.dumps(doc, indent=2))
    columns = result.series.columns()
    table = np.array(list(columns.values()), dtype=float).T
    with atomic_path(out_dir / "timeseries.csv") as tmp:
        np.savetxt(tmp, table, delimiter=",", header=",".join(columns), comments="", fmt="%.6g")
    if plot is not None:
        plot(result, out_dir / "timeseries.png")
