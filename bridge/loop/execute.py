"""Execute one RunSpec: the one place a closed-loop run is assembled and torn down.

:func:`start` brings a run to its first step (road, SUMO, warm-up, ScenarioEngine with the
Init actions and the checks of the actions they decide, ego stack) and always closes SUMO;
:func:`execute` runs it with its recording and result files; :func:`check` makes every check
of :func:`start` and runs nothing (``--dry-run``).

Use::

    (run,) = load_plan("cut_in.xosc").expand()
    with run.spec() as spec:
        result = execute(spec, RunOptions(out_dir=Path("out/cut_in"), record=True))
"""

from __future__ import annotations

import contextlib
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from hiyari.bridge.loop.closed_loop import OnStep, run_closed_loop
from hiyari.bridge.loop.decided import DecidedEnd
from hiyari.bridge.loop.hooks import EngineHooks
from hiyari.bridge.loop.result import PlotRun, RunResult, write_result
from hiyari.bridge.loop.spec import RunSpec, StackContext, default_stack, import_road
from hiyari.bridge.loop.stack.aeb import AEBPlanner
from hiyari.bridge.loop.stack.interfaces import EgoStack
from hiyari.bridge.loop.stack.perception_sensors import SensorPerception
from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.record.format import PART_SUFFIX
from hiyari.errors import HiyariError, WriteFailed, unmasked_interrupts
from hiyari.net.road.network import RoadNetwork
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.road.sumo_roads import sumo_road_lanes
from hiyari.traffic.simulation import Simulation

if TYPE_CHECKING:
    from hiyari.bridge.record.recorder import RecorderConfig


@dataclass(frozen=True)
class RunOptions:
    """How to run: write result files to ``out_dir`` (None: results only), show a progress
    bar, record (``record``: ``out_dir/run.mcap``; or ``recording``: this file)."""

    out_dir: Path | None = None
    progress: bool = False
    #: draws the run's time series into the given PNG path (None: no figure); the studies' report
    #: wing has one (hiyari.bridge.studies.report.timeseries.plot_timeseries)
    plot: PlotRun | None = None
    record: bool = False  # write out_dir/run.mcap (needs out_dir)
    recording: Path | None = None  # write the recording to this file instead
    camera_image_every: int = 10  # when recording: render every Nth camera frame (0: none)
    recorder: RecorderConfig | None = None  # when recording: how (None: the defaults)
    #: end once the rest of the run cannot change its judged values (bridge.loop.decided)
    end_when_decided: bool = False

    def __post_init__(self) -> None:
        if self.record and self.out_dir is None:
            raise HiyariError("recording needs an output folder")

    def recording_path(self) -> Path | None:
        """The MCAP file the run records to (None: no recording)."""
        if self.recording is not None:
            return self.recording
        return self.out_dir / "run.mcap" if self.record else None


@dataclass(frozen=True)
class Started:
    """A run at its first step: SUMO, the engine's hooks, the ego stack and the road."""

    sim: Simulation
    hooks: EngineHooks
    stack: EgoStack
    network: RoadNetwork


@contextlib.contextmanager
def start(spec: RunSpec, work: Path) -> Iterator[Started]:
    """Everything a run does before its first step: the road (imported into ``work`` when the
    spec has no net), SUMO started and warmed up, the Init actions applied and the
    storyboard's statically decided actions checked (ScenarioEngine.start), the ego stack
    built; SUMO is closed on leaving, whatever happens."""
    sc, road, ego = spec.scenario, spec.road, spec.ego
    if sc.ego is None:
        raise HiyariError(f"{sc.source or sc.name}: the scenario has no ego")
    net = road.net if road.net is not None else import_road(sc, work)
    network = road.network if road.network is not None else RoadNetwork(net)
    lanes = road.lanes
    if lanes is None:  # a generated net without OpenDRIVE: its edges are the roads
        xodr = road.xodr
        lanes = RoadLanes.from_files(xodr, net) if xodr is not None else sumo_road_lanes(network)
    with Simulation(road.sim_config(net, ego, spec.sumo_args)) as sim:
        if spec.warmup > 0:
            sim.fast_forward(sim.time + spec.warmup)
        engine = ScenarioEngine(sc, lanes, ego.step_length)
        hooks = (spec.hooks or EngineHooks)(engine, sim, spec.scoring)
        set_speed = ego.set_speed
        if set_speed is None:
            set_speed = engine.ego_set_speed()
        ctx = StackContext(network, ego, sc.ego, set_speed, sc, spec.warm, engine.environment)
        yield Started(sim, hooks, (ego.stack or default_stack)(ctx), network)


def check(spec: RunSpec) -> None:
    """Every check a run of ``spec`` makes before its first step (:func:`start`), in a
    temporary folder: nothing is written, nothing is run."""
    with tempfile.TemporaryDirectory(prefix="hiyari-run-") as tmp, start(spec, Path(tmp)):
        pass


def execute(
    spec: RunSpec, options: RunOptions | None = None, on_step: OnStep | None = None
) -> RunResult:
    """Run ``spec`` once in closed loop in this process (one libsumo simulation at a time).

    With ``options.out_dir``: result.json, timeseries.csv (and .png with ``options.plot``);
    the recording when asked. A run that fails or is interrupted leaves no output under a
    final name (:func:`run_folder`). ``on_step(world, ego_step, collisions)`` after every
    stack step."""
    options = options or RunOptions()
    with (
        run_folder(options),
        unmasked_interrupts(),
        tempfile.TemporaryDirectory(prefix="hiyari-run-") as tmp,
    ):
        with start(spec, Path(tmp)) as run:
            decided = _decided_end(spec, run) if options.end_when_decided else None
            with recording(spec, run, options) as recorder:
                result = run_closed_loop(
                    run.sim, run.stack, run.hooks, spec.ego.max_duration, label=spec.label,
                    on_step=chain(recorder, on_step), progress=options.progress,
                    decided=decided, open_ended=bool(spec.scenario.storyboard.stop_trigger),
                )  # fmt: skip
        if options.out_dir is not None:
            write_result(result, spec.doc, options.out_dir, plot=options.plot)
    return result


@contextlib.contextmanager
def run_folder(options: RunOptions) -> Iterator[None]:
    """Around one run: when it fails (an error, not an interrupt), remove its recording's
    ``.part`` file, and ``out_dir`` when the run made it and nothing else is in it. An
    interrupted run, or one stopped by a full disk, keeps the ``.part`` file: readable up to
    the interrupt (``hiyari replay --recover``) and never taken for a finished recording."""
    out_dir, path = options.out_dir, options.recording_path()
    made_out = out_dir is not None and not out_dir.exists()
    try:
        yield
    except Exception as exc:
        if path is not None and not isinstance(exc, WriteFailed):
            path.with_name(path.name + PART_SUFFIX).unlink(missing_ok=True)
        if made_out and out_dir.is_dir() and not any(out_dir.iterdir()):
            out_dir.rmdir()
        raise


@contextlib.contextmanager
def recording(spec: RunSpec, run: Started, options: RunOptions) -> Iterator[OnStep | None]:
    """The ``on_step`` that records every step when ``options`` ask for a recording (None
    otherwise); the recorder is closed on leaving: complete after the run, under its ``.part``
    name when the run failed or was interrupted."""
    from hiyari.bridge.loop.recording import StepRecorder, open_recorder

    path = options.recording_path()
    if path is None:
        yield None
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    sim, stack = run.sim, run.stack
    links = sim.signal_links()
    recorder = open_recorder(path, spec.metadata, stack, run.network, links, options.recorder)
    if isinstance(stack.perception, SensorPerception):
        stack.perception.render_every = options.camera_image_every
    signals = sim.signal_states if links else None
    try:
        yield StepRecorder(recorder, stack, run.hooks.ego_id, signals)
    except BaseException:
        recorder.close(complete=False)
        raise
    recorder.close()


def _decided_end(spec: RunSpec, run: Started) -> DecidedEnd | None:
    """The decided-end test of a run of vehicles on a road without SUMO traffic, the ego
    driven by the default planner (None for anything else, and for an ego on its Init ramp)."""
    engine: ScenarioEngine = run.hooks.engine
    if spec.road.has_demand() or not isinstance(run.stack.planner, AEBPlanner):
        return None
    if engine.ego_ramp is not None:  # the Init ramp accelerates beyond the ACC's law
        return None
    return DecidedEnd.of(engine, run.stack.planner.acc, spec.ego.step_length, spec.scoring.target)


def chain(first: OnStep | None, second: OnStep | None) -> OnStep | None:
    """Call ``first`` and then ``second`` (either may be None) with the same arguments."""
    if first is None or second is None:
        return first or second

    def both(*args: object) -> None:
        first(*args)
        second(*args)

    return both
