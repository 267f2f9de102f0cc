"""TOML scenario files as runs: each concrete scenario of a logical one compiles to a RunSpec,
its type's preset of the scenario model on the road the preset generates
(hiyari.bridge.openscenario.presets.scenarios), run by the ScenarioEngine as an OpenSCENARIO
file is.

A preset's scenario is computed on its road (edge ids, lane offsets, the city route), so
compiling one writes the road: into a folder given (:func:`preset_spec`) or a temporary one
(:meth:`TomlRun.spec`), or takes it from a process's WarmCache (built there once).
"""

from __future__ import annotations

import contextlib
import math
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path

from hiyari.bridge.loop.spec import EgoSetup, Road, RunSpec, load_stack
from hiyari.bridge.loop.warm import WarmCache
from hiyari.bridge.openscenario.presets.scenarios import World, build_scenario
from hiyari.bridge.openscenario.presets.toml_file import (
    PARAMETERS,
    ConcreteScenario,
    LogicalScenario,
)
from hiyari.errors import HiyariError
from hiyari.units import kmh_to_mps


def preset_doc(cs: ConcreteScenario) -> dict:
    """A TOML concrete scenario as result.json's scenario section records it."""
    return {
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


def preset_metadata(cs: ConcreteScenario) -> dict:
    """A TOML concrete scenario as the recording's metadata records it."""
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


def preset_spec(
    cs: ConcreteScenario, work: Path, warm: WarmCache | None = None, world: World | None = None
) -> RunSpec:
    """The run of one concrete scenario: its preset built with road files written into
    ``work`` (or taken from ``warm``, built there once per process); ``world``: a city run's
    map or SUMO scenario (None: the generated city). The ego's ACC set speed is ``ve0_kmh``;
    ``cs.stack`` names a stack factory (``ego.stack``)."""
    preset = build_scenario(cs, work, roads=warm, world=world)
    network = preset.network
    ego = EgoSetup(
        perception=cs.perception,
        sensors=cs.sensors,
        environment=cs.environment,
        aeb_delay=cs.aeb_delay,
        set_speed=kmh_to_mps(cs.params.get("ve0_kmh", 40.0)),
        step_length=cs.step_length,
        seed=cs.seed,
        max_duration=cs.duration,
        stack=load_stack(cs.stack, "ego.stack") if cs.stack else None,
    )
    road = Road(
        net=network.path, network=network, lanes=preset.roads, routes=preset.routes,
        sumo=preset.sumo, user_net=world is not None,
    )  # fmt: skip
    return RunSpec(
        preset.scenario, road, ego, preset.scoring, preset.warmup, label=cs.label(),
        doc=preset_doc(cs), metadata=preset_metadata(cs), warm=warm,
    )  # fmt: skip


@dataclass(frozen=True)
class TomlRun:
    """One concrete run of a TOML file (``scenario``) and the world a city run drives in."""

    scenario: ConcreteScenario
    world: World | None = None

    @property
    def index(self) -> int:
        """The run's index in its file's expansion."""
        return self.scenario.index

    @property
    def seed(self) -> int:
        """The run's seed (SUMO and sensors)."""
        return self.scenario.seed

    @property
    def params(self) -> dict[str, float]:
        """The run's parameter values (units as their names give)."""
        return self.scenario.params

    def label(self) -> str:
        """Short id, e.g. 'cut-in#3 ve0_kmh=60 vo0_kmh=20'."""
        return self.scenario.label()

    @contextlib.contextmanager
    def spec(self) -> Iterator[RunSpec]:
        """The run's spec, its road in a temporary folder removed on leaving."""
        with tempfile.TemporaryDirectory(prefix="hiyari-road-") as tmp:
            yield preset_spec(self.scenario, Path(tmp), world=self.world)


@dataclass(frozen=True)
class TomlPlan:
    """The runs of a TOML logical scenario (``logical``), with the command line's ``perception``
    and ``environment`` over the file's (None: the file's) and a city run's ``world``."""

    logical: LogicalScenario
    world: World | None = None
    perception: str | None = None
    environment: str | None = None

    def __post_init__(self) -> None:
        if self.world is not None and self.logical.type != "city":
            raise HiyariError(
                f"{self.logical.path}: a {self.logical.type} scenario runs on its own road "
                "(--sumocfg and --map apply to city scenarios)"
            )

    @property
    def path(self) -> str:
        """The file, as given."""
        return self.logical.path

    @property
    def name(self) -> str:
        """The scenario's name."""
        return self.logical.name

    @property
    def parameter_names(self) -> list[str]:
        """Every parameter of the scenario's type, in table order."""
        return list(PARAMETERS[self.logical.type])

    @property
    def varied(self) -> list[str]:
        """The parameters that change between runs (the sweep plot's axes)."""
        return [*self.logical.ranges, *self.logical.random]

    def count(self) -> int:
        """How many runs, computed from the axis lengths (nothing is expanded)."""
        lg = self.logical
        if lg.sampling.get("mode", "grid") == "random":
            return int(lg.sampling.get("n", 0))
        return math.prod(len(v) for v in lg.ranges.values())

    @property
    def skipped(self) -> tuple[()]:
        """None: a TOML file's ranges have no constraints."""
        return ()

    def expand(self) -> list[TomlRun]:
        """The concrete runs, run ``k`` seeded ``seed + k``."""
        runs = self.logical.expand()
        if self.perception:
            runs = [replace(cs, perception=self.perception) for cs in runs]
        if self.environment is not None:
            runs = [replace(cs, environment=self.environment) for cs in runs]
        return [TomlRun(cs, self.world) for cs in runs]

    def with_roads(self, folder: Path) -> TomlPlan:
        """This plan (each run builds its own road when it is compiled)."""
        return self
