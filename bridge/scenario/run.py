"""Run one concrete scenario end to end: road, SUMO, ego stack, metrics, files, plot."""

from __future__ import annotations

import importlib
import json
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from hiyari.atomic import atomic_path
from hiyari.bridge.scenario.closed_loop import OnStep
from hiyari.bridge.scenario.decided import DecidedEnd
from hiyari.bridge.scenario.engine import ScenarioEngine
from hiyari.bridge.scenario.presets import build_scenario
from hiyari.bridge.scenario.result import RunResult, TimeSeries
from hiyari.bridge.scenario.toml_file import ConcreteScenario
from hiyari.bridge.scenario.warm import WarmCache
from hiyari.bridge.stack.aeb import ACCConfig, AEBConfig, AEBPlanner
from hiyari.bridge.stack.fusion import KalmanFusion
from hiyari.bridge.stack.interfaces import EgoStack
from hiyari.bridge.stack.perception_sensors import SensorPerception
from hiyari.bridge.stack.perception_truth import NoPerception, PerfectPerception
from hiyari.errors import HiyariError
from hiyari.net.road.network import RoadNetwork
from hiyari.sensors.environment.presets import disturbance_preset
from hiyari.traffic.simulation import SimConfig, Simulation
from hiyari.units import G, kmh_to_mps, mps_to_kmh

if TYPE_CHECKING:
    from hiyari.bridge.record.recorder import RecorderConfig

#: Threads each run's static ray casts are split over (same hits for any number).
CAST_WORKERS = 2


@dataclass(frozen=True)
class RunOptions:
    """How to run: write files to ``out_dir`` (None: results only), show a progress bar."""

    out_dir: Path | None = None
    progress: bool = False
    plot: bool = True
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
) -> RunResult:
    """Run one concrete scenario in this process (one libsumo simulation at a time): its
    type's preset of the scenario model, run by the ScenarioEngine in the closed loop every
    scenario runs in (bridge.scenario.engine_run).

    ``warm``: take the road, its ray-cast scene and the sensor rig from this process's cache
    (built by the first run on that road) instead of building them; same results.
    """
    # engine_run builds on this module (RunOptions, write_result): imported here
    from hiyari.bridge.scenario.engine_run import EngineHooks, drive

    options = options or RunOptions()
    with tempfile.TemporaryDirectory(prefix="hiyari-run-") as tmp:
        work = options.out_dir / "roads" if options.out_dir else Path(tmp)
        preset = build_scenario(cs, work, roads=warm)
        network = preset.network
        stack = build_stack(cs, network, warm)
        net = network.path
        cfg = SimConfig(
            net=net,
            routes=preset.routes,
            step_length=cs.step_length,
            seed=cs.seed,
            generated=(net, *preset.routes),
        )
        with Simulation(cfg) as sim:
            sim.fast_forward(preset.warmup)
            engine = ScenarioEngine(preset.scenario, preset.roads, cs.step_length)
            hooks = EngineHooks(engine, sim, preset.scoring)
            decided = None
            if options.end_when_decided:
                decided = decided_end(
                    engine, preset.routes, stack, cs.step_length, preset.scoring.target
                )
            result = drive(
                sim, stack, hooks, cs.label(), cs.duration, options, network,
                concrete_metadata(cs), on_step, decided,
            )  # fmt: skip
    if options.out_dir is not None:
        write_result(result, cs, options.out_dir, plot=options.plot)
    return result


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
    result: RunResult, scenario: ConcreteScenario | dict, out_dir: Path, plot: bool = True
) -> None:
    """result.json (summary + parameters), timeseries.csv and timeseries.png in ``out_dir``.
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
    if plot:
        plot_timeseries(result, out_dir / "timeseries.png")


def plot_timeseries(result: RunResult, out: Path) -> Path:
    """Write :func:`timeseries_figure` as PNG."""
    fig = timeseries_figure(result)
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return out


#: acceleration command (m/s^2) below which the ACC counts as braking
ACC_BRAKING = -0.3


def _spans(t: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """Time spans (s) of the runs of ``mask``, each sample holding until the next one (so a
    single sample still shows as one step wide)."""
    if t.size == 0:
        return []
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.05
    ends = np.append(t[1:], t[-1] + step)
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return [
        (float(t[a]), float(ends[b - 1]))
        for a, b in zip(*[np.flatnonzero(edges == e) for e in (1, -1)], strict=True)
    ]


def _braking_phases(s: TimeSeries) -> list[tuple[str, str, np.ndarray]]:
    """What the controller did, per sample: (label, colour, mask). The AEB by the deceleration
    it applied (each level its own shade), the ACC where it braked on its own."""
    accel = np.asarray(s.ego_accel_cmd, dtype=float)
    aeb = np.asarray(s.aeb_decel, dtype=float) if s.aeb_decel else np.zeros(accel.shape)
    phases = []
    levels = np.unique(np.round(aeb[aeb > 0] / G, 2))
    colours = ["#ffc078", "#ff8787", "#e599f7"]
    for k, level in enumerate(levels):
        on = np.isclose(np.round(aeb / G, 2), level)
        phases.append((f"AEB braking {level:g} g", colours[min(k, len(colours) - 1)], on))
    acc = (aeb <= 0) & (accel < ACC_BRAKING)
    if acc.any():
        phases.append((f"ACC braking (< {ACC_BRAKING:g} m/s²)", "#a5d8ff", acc))
    return phases


def timeseries_figure(result: RunResult) -> Figure:
    """Speed, acceleration command, gap and TTC over time, shaded by what the controller did
    (AEB braking by level, ACC braking), with the AEB stage decisions marked."""
    s = result.series
    t = np.asarray(s.t)
    fig = Figure(figsize=(8.5, 8.5), layout="constrained")
    axes = fig.subplots(4, 1, sharex=True)
    axes[0].plot(t, mps_to_kmh(np.asarray(s.ego_speed)), label="ego speed")
    axes[0].set_ylabel("speed (km/h)")
    axes[1].plot(t, np.asarray(s.ego_accel_cmd), color="k", lw=1.2, label="command")
    if s.aeb_decel:
        axes[1].plot(t, -np.asarray(s.aeb_decel), "--", color="tab:red", label="AEB applied")
    axes[1].set_ylabel("acceleration (m/s²)")
    gap = np.asarray(s.gap, dtype=float)
    gap_label = "gap to target"
    if s.conflict_distance:
        gap, gap_label = np.asarray(s.conflict_distance), "distance to conflict point"
    axes[2].plot(t, np.where(np.isfinite(gap), gap, np.nan), color="tab:orange", label=gap_label)
    axes[2].axhline(0, color="k", lw=0.6)
    axes[2].set_ylabel("distance (m)")
    for values, lab, style in (
        (s.ttc_true, "TTC (ground truth)", "-"),
        (s.ttc_stack, "TTC (ego stack)", "--"),
    ):
        v = np.asarray(values, dtype=float)
        axes[3].plot(t, np.where(v < 10, v, np.nan), style, label=lab)
    axes[3].set_ylim(0, 10)
    axes[3].set_ylabel("TTC (s)")
    axes[3].set_xlabel("simulation time (s)")
    phases = _braking_phases(s)
    stage = np.asarray(s.aeb_stage)
    decided = [(lvl, t[np.flatnonzero(stage >= lvl)[0]]) for lvl in (2, 3) if (stage >= lvl).any()]
    for ax in axes:
        for _, colour, mask in phases:
            for a, b in _spans(t, mask):
                ax.axvspan(a, b, color=colour, alpha=0.6, lw=0)
        for _, when in decided:
            ax.axvline(when, color="tab:red", lw=0.8, ls=":")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    handles = [Patch(color=c, alpha=0.6, label=lab) for lab, c, _ in phases]
    names = {2: "partial", 3: "full"}
    handles += [
        Line2D(
            [],
            [],
            color="tab:red",
            lw=0.8,
            ls=":",
            label=f"AEB decides {names[lvl]} at {when:.2f} s",
        )
        for lvl, when in decided
    ]
    if handles:
        fig.legend(
            handles=handles, loc="outside lower center", ncol=min(len(handles), 3), fontsize=8
        )
    verdict = (
        f"COLLISION with {result.collided_with} at {mps_to_kmh(result.impact_speed):.1f} km/h"
        if result.collision
        else "no collision"
    )
    shaded = "; shaded: what the controller did" if phases else "; no braking"
    fig.suptitle(f"{result.label}\n{verdict}{shaded}", fontsize=9)
    return fig
