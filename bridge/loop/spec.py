"""One closed-loop run, whatever it came from: a TOML preset, an OpenSCENARIO file, a catalogue
case or an R157 test point all compile to a :class:`RunSpec` (the scenario model, its road,
the ego setup, scoring, warm-up and how the run is labelled), which
:func:`hiyari.bridge.loop.execute.execute` runs.

The ego stack has one contract for every entry point: a :data:`StackFactory` called once per
run with a :class:`StackContext`, after the Init actions are applied (``ego.stack`` of a TOML
file, ``--stack`` of ``hiyari evaluate`` and ``EgoSetup.stack`` in Python name one).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, Sequence
from contextlib import AbstractContextManager
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from hiyari.bridge.loop.scenario_environment import disturbance_from, grip
from hiyari.bridge.loop.stack.aeb import ACCConfig, AEBConfig, AEBPlanner
from hiyari.bridge.loop.stack.fusion import KalmanFusion
from hiyari.bridge.loop.stack.interfaces import EgoStack, Perception
from hiyari.bridge.loop.stack.perception_sensors import SensorPerception
from hiyari.bridge.loop.stack.perception_truth import NoPerception, PerfectPerception
from hiyari.bridge.loop.warm import WarmCache
from hiyari.bridge.openscenario.model.global_actions import Environment as ScenarioEnvironment
from hiyari.bridge.openscenario.model.scoring import Scoring
from hiyari.bridge.openscenario.model.storyboard import Scenario
from hiyari.bridge.openscenario.presets.toml_file import PERCEPTION_MODES, SENSOR_NAMES
from hiyari.errors import HiyariError
from hiyari.net.road.network import RoadNetwork
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.sensors.environment.presets import disturbance_preset
from hiyari.traffic.simulation import SimConfig
from hiyari.traffic.sumocfg import SumoScenario

if TYPE_CHECKING:
    from hiyari.bridge.loop.hooks import HooksFactory

#: The environment name under which the sensors see the scenario's own EnvironmentAction.
SCENARIO_ENVIRONMENT = "scenario"

#: Threads each run's static ray casts are split over (same hits for any number).
CAST_WORKERS = 2


@dataclass(frozen=True)
class StackContext:
    """What a stack factory gets: the run's road, ego setup, the ego's id and its ACC set
    speed (m/s), the scenario, this process's cache of ray-cast scenes and sensor rigs (None:
    build them for this run), and the environment the scenario's Init actions set (None:
    none)."""

    network: RoadNetwork
    setup: EgoSetup
    ego_id: str
    set_speed: float
    scenario: Scenario
    warm: WarmCache | None = None
    environment: ScenarioEnvironment | None = None


#: Builds the ego stack of one run (called once, after the Init actions are applied).
StackFactory = Callable[[StackContext], EgoStack]


@dataclass(frozen=True)
class EgoSetup:
    """The ego and the run's clock.

    ``perception``: perfect | sensors | none; ``sensors`` used with "sensors"; ``environment``
    a disturbance preset; ``aeb_delay`` s; ``set_speed`` the ACC set speed, m/s (None: the
    ego's speed after the Init actions); ``step_length`` s; ``seed`` SUMO's and the sensors'
    seed; ``max_duration`` s of scenario time after which the run ends if the stop trigger
    has not fired; ``stack`` builds the ego stack (None: :func:`default_stack`, which uses the
    settings above)."""

    perception: str = "perfect"
    sensors: tuple[str, ...] = SENSOR_NAMES
    environment: str = "clear"
    aeb_delay: float = 0.2
    set_speed: float | None = None
    step_length: float = 0.05
    seed: int = 1
    max_duration: float = 600.0
    stack: StackFactory | None = None

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

    def as_dict(self) -> dict:
        """The settings as result.json records them (seed and stack left out)."""
        return {
            f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("seed", "stack")
        }


def default_perception(ctx: StackContext) -> Perception:
    """The setup's perception: perfect, none, or the default sensor rig, casting into
    ``ctx.warm``'s scene of the road when there is one (built once per process). With the
    environment "scenario" the sensors see the scenario's EnvironmentAction (clear when it
    has none)."""
    s = ctx.setup
    preset = disturbance_preset(s.environment if s.environment != SCENARIO_ENVIRONMENT else "clear")
    if s.environment == SCENARIO_ENVIRONMENT and ctx.environment is not None:
        preset = disturbance_from(ctx.environment)
    if s.perception == "perfect":
        return PerfectPerception()
    if s.perception == "none":
        return NoPerception()
    if ctx.warm is not None:
        scene = ctx.warm.scene(ctx.network, buildings=False, workers=CAST_WORKERS)
        rig = ctx.warm.rig(s.sensors)
        return SensorPerception(scene, rig, preset, ctx.ego_id, s.step_length, s.seed)
    return SensorPerception.default_rig(
        ctx.network, s.sensors, s.environment, s.step_length, s.seed, ctx.ego_id,
        workers=CAST_WORKERS, preset=preset,
    )  # fmt: skip


def default_stack(ctx: StackContext) -> EgoStack:
    """hiyari's stack: :func:`default_perception`, Kalman fusion, ACC + AEB; the road's
    friction (the scenario's environment) scales the decelerations the planner commands."""
    mu = min(1.0, grip(ctx.environment))
    aeb = AEBConfig(actuation_delay=ctx.setup.aeb_delay)
    aeb = replace(aeb, partial_decel_g=aeb.partial_decel_g * mu, full_decel_g=aeb.full_decel_g * mu)
    acc = ACCConfig(set_speed=ctx.set_speed)
    planner = AEBPlanner(replace(acc, max_decel=acc.max_decel * mu), aeb)
    return EgoStack(default_perception(ctx), KalmanFusion(), planner)


def load_stack(name: str, where: str) -> StackFactory:
    """The user's stack factory named "module:callable"; ``where`` names the option or key
    that gave it in the one-line error."""
    module, _, attr = name.partition(":")
    try:
        return getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError, ValueError) as exc:
        raise HiyariError(f"{where}: cannot load {name!r}: {exc}") from None


@dataclass(frozen=True)
class Road:
    """Where a run drives. ``xodr``: the OpenDRIVE road the scenario's positions refer to
    (None: the net's own edges are the roads, as on a generated SUMO road); ``net``: the SUMO
    net (None: imported from ``xodr`` when the run starts); ``network`` / ``lanes``: the
    parsed road when the compiler has it (else parsed when the run starts); ``routes``: SUMO's
    own demand; ``sumo``: a user's SUMO scenario, run as its .sumocfg says instead of net and
    routes; ``user_net``: the net is the user's own (a map): SUMO's load errors name it."""

    xodr: Path | None = None
    net: Path | None = None
    network: RoadNetwork | None = None
    lanes: RoadLanes | None = None
    routes: tuple[Path, ...] = ()
    sumo: SumoScenario | None = None
    user_net: bool = False

    def has_demand(self) -> bool:
        """Whether SUMO brings its own traffic (routes or a SUMO scenario)."""
        return bool(self.routes) or self.sumo is not None

    def sim_config(self, net: Path, ego: EgoSetup, extra_args: tuple[str, ...]) -> SimConfig:
        """What SUMO runs on the road's net ``net`` at the run's step and seed."""
        if self.sumo is not None:  # the user's scenario as SUMO runs it, at the run's step
            return SimConfig.from_sumocfg(self.sumo.config, ego.step_length, ego.seed)
        generated = self.routes if self.user_net else (net, *self.routes)
        return SimConfig(
            net=net, routes=self.routes, step_length=ego.step_length, seed=ego.seed,
            generated=generated, extra_args=extra_args,
        )  # fmt: skip


def import_road(scenario: Scenario, workdir: Path) -> Path:
    """The SUMO net of the scenario's OpenDRIVE road, imported into ``workdir``."""
    from hiyari.net.sumo.opendrive import import_opendrive

    xodr = scenario.road_network
    if xodr is None:
        raise HiyariError(f"{scenario.source or scenario.name}: the scenario names no road")
    workdir.mkdir(parents=True, exist_ok=True)
    return import_opendrive(xodr, workdir / f"{Path(xodr).stem}.net.xml")


def sumo_road(
    scenario: Scenario, sumo: SumoScenario, imported: Path, warmup: float, duration: float
) -> Road:
    """The road of an OpenSCENARIO run inside the user's SUMO scenario ``sumo``: its net must
    be the SUMO conversion of the OpenDRIVE road the scenario names (the same edges and lanes
    as ``imported``, hiyari's import of it), since the storyboard's positions are OpenDRIVE
    road / lane / s and SUMO runs the scenario's own net; the run (``warmup`` s of the
    scenario's demand, then at most ``duration`` s) must end inside its time window.
    HiyariError (one line naming the .sumocfg) otherwise."""
    from hiyari.bridge.openscenario.presets.scenarios import World
    from hiyari.net.sumo.files import road_difference

    xodr = scenario.road_network
    if xodr is None:
        raise HiyariError(f"{scenario.source or scenario.name}: the scenario names no road")
    differs = road_difference(sumo.net, imported)
    if differs is not None:
        raise HiyariError(
            f"{sumo.config}: its net {sumo.net.name} is not the conversion of {xodr.name}, the "
            f"road the OpenSCENARIO file names ({differs}); make it with 'hiyari net import "
            f"{xodr.name}'"
        )
    if sumo.end is not None and sumo.begin + warmup + duration > sumo.end:
        raise HiyariError(
            f"{sumo.config}: the run (warmup {warmup:g} s + max duration {duration:g} s from "
            f"begin {sumo.begin:g} s) ends after the scenario's end {sumo.end:g} s"
        )
    network = World(sumo.net, sumo).network()  # with the scenario's buildings
    return Road(xodr, sumo.net, network, sumo=sumo, user_net=True)


@dataclass(frozen=True)
class RunSpec:
    """One closed-loop run: the scenario model the ScenarioEngine runs on ``road``, the ego
    (``ego``: its stack, perception and the run's clock), how the run is scored (``scoring``:
    the gap's target, conflict point and settle rule) and ``warmup`` s SUMO runs its own
    traffic before the scenario starts.

    How it is written down: ``label`` names the run in its result, ``doc`` is result.json's
    scenario section and ``metadata`` the recording's (a table's parameter columns come from
    the planned run, which has them even when its spec cannot be compiled). ``hooks`` builds the closed loop's scenario hooks (None:
    EngineHooks), ``sumo_args`` are extra SUMO options, ``warm`` is this process's cache the
    compiler took roads from (the default stack takes its scene and rig from it too)."""

    scenario: Scenario
    road: Road
    ego: EgoSetup = field(default_factory=EgoSetup)
    scoring: Scoring = field(default_factory=Scoring)
    warmup: float = 0.0
    label: str = ""
    doc: Mapping[str, object] = field(default_factory=dict)
    metadata: Mapping[str, object] = field(default_factory=dict)
    hooks: HooksFactory | None = None
    sumo_args: tuple[str, ...] = ()
    warm: WarmCache | None = None


def scenario_doc(scenario: Scenario, setup: EgoSetup) -> dict:
    """A model scenario and its ego setup as result.json / recording metadata record them."""
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
        **setup.as_dict(),
    }


def model_spec(
    scenario: Scenario, setup: EgoSetup | None = None, net: Path | None = None
) -> RunSpec:
    """The run of a model scenario (an OpenSCENARIO file read, or one built in Python) on its
    OpenDRIVE road: ``net`` the SUMO net already imported from it (None: imported when the
    run starts). Ends at the stop trigger, a collision of the ego, the ego leaving the
    network or ``setup.max_duration``."""
    setup = setup or EgoSetup()
    doc = scenario_doc(scenario, setup)
    return RunSpec(
        scenario,
        Road(scenario.road_network, net),
        setup,
        label=scenario.name,
        doc=doc,
        metadata={**doc, "scenario": scenario.name},
    )


class PlannedRun(Protocol):
    """One run of a scenario file (TOML or OpenSCENARIO): its index in the file's expansion,
    seed and parameter values (table columns), and its spec (valid inside the ``with``)."""

    @property
    def index(self) -> int: ...

    @property
    def seed(self) -> int: ...

    @property
    def params(self) -> Mapping[str, object]: ...

    def label(self) -> str:
        """Short id of the run."""
        ...

    def spec(self) -> AbstractContextManager[RunSpec]:
        """The run compiled (its road files exist inside the ``with``)."""
        ...


@dataclass(frozen=True)
class SkippedRun:
    """A run of a scenario file that is not executed: its parameter set breaks the scenario's
    ConstraintGroups (``reason``: the parameters, their values and the bounds broken). It
    keeps its index and seed in the file's expansion, as if it had run."""

    index: int
    seed: int
    params: Mapping[str, object]
    reason: str
    name: str = ""

    def label(self) -> str:
        """'cut_in#3: skipped (constraint: Offset = -1.75 breaks greaterThan -1.75)'."""
        return f"{self.name}#{self.index}: skipped (constraint: {self.reason})"


def count_text(plan: Plan) -> str:
    """'N runs' or 'N runs, M skipped: constraint' (N counts the skipped ones: every run the
    file defines)."""
    m = len(plan.skipped)
    n = plan.count() + m
    return f"{n} run(s)" + (f", {m} skipped: constraint" if m else "")


class Plan(Protocol):
    """The runs of a scenario file (TOML logical scenario, or an OpenSCENARIO scenario or
    parameter distribution), counted before anything is expanded."""

    @property
    def path(self) -> str: ...

    @property
    def name(self) -> str: ...

    @property
    def parameter_names(self) -> list[str]:
        """Every parameter a run sets (table columns)."""
        ...

    @property
    def varied(self) -> list[str]:
        """The numeric parameters that change between runs."""
        ...

    def count(self) -> int:
        """How many runs are executed (nothing expanded; the skipped ones not counted)."""
        ...

    @property
    def skipped(self) -> Sequence[SkippedRun]:
        """The runs not executed because their parameters break the scenario's constraints."""
        ...

    def expand(self) -> Sequence[PlannedRun]:
        """The runs, run ``k`` seeded ``seed + k``."""
        ...

    def with_roads(self, folder: Path) -> Plan:
        """This plan with the road its runs share made once in ``folder`` (where they share
        one)."""
        ...
