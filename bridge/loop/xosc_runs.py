"""OpenSCENARIO files as runs: a scenario file is one run, a ParameterValueDistribution file
the runs of its parameter sets; each run reads its scenario with its parameter values and
compiles to a RunSpec (:func:`~hiyari.bridge.loop.spec.model_spec`).

A run whose parameter set breaks the scenario's ConstraintGroups is skipped, not executed
(OpenSCENARIO 1.3: the constraints define the valid parameter values; a set outside them is not
a valid concrete scenario). Every run's set is checked against the top-level
ParameterDeclarations only, so that a distribution of thousands of runs is not read thousands
of times; a skipped run keeps its index and seed, and is listed with the values and evaluated
bounds it breaks. The plan then reads and checks the scenario with the first executed run's
values before anything runs (a bad file, parameter, catalog or road is one line naming the
file and element, and nothing is written); run ``k`` is seeded ``seed + k`` as TOML runs are.
"""

from __future__ import annotations

import contextlib
import tempfile
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, replace
from pathlib import Path

from hiyari.bridge.loop.spec import (
    EgoSetup,
    RunSpec,
    SkippedRun,
    import_road,
    model_spec,
    sumo_road,
)
from hiyari.bridge.openscenario.model.storyboard import Scenario
from hiyari.bridge.openscenario.xosc import document
from hiyari.bridge.openscenario.xosc.context import INT_TYPES, ConstraintViolation, Ctx, Scope
from hiyari.bridge.openscenario.xosc.distributions import read_distribution
from hiyari.bridge.openscenario.xosc.reader import no_ego, read_scenario
from hiyari.errors import HiyariError
from hiyari.traffic.sumocfg import SumoScenario


@dataclass(frozen=True)
class XoscRun:
    """One concrete run: the scenario file, its parameter values (file text) and the ego setup
    (``setup.seed`` is this run's seed). ``road_net``: an OpenDRIVE file and the SUMO net
    already imported from it (used when the scenario's road is that file). ``sumo``: the user's SUMO scenario
    the run drives inside (its net the conversion of the scenario's road), its demand running
    ``warmup`` s before the storyboard starts."""

    scenario: Path
    name: str
    index: int
    params: dict[str, str]
    setup: EgoSetup
    road_net: tuple[Path, Path] | None = None
    type: str = "openscenario"
    sumo: SumoScenario | None = None
    warmup: float = 0.0
    ego: str | None = None  # the ego entity's name (None: the reader picks it)

    @property
    def seed(self) -> int:
        """The run's seed (SUMO and sensors)."""
        return self.setup.seed

    def label(self) -> str:
        """Short id, e.g. 'cut_in#3 Ego_InitSpeed_Ve0_kph=60.0'."""
        vals = " ".join(f"{k}={v}" for k, v in self.params.items())
        return f"{self.name}#{self.index}" + (f" {vals}" if vals else "")

    def load(self) -> Scenario:
        """The scenario with this run's parameter values."""
        return read_scenario(self.scenario, self.params, self.ego)

    @contextlib.contextmanager
    def spec(self) -> Iterator[RunSpec]:
        """The run's spec: the scenario read with this run's values, on the road imported
        for the plan (or imported when the run starts)."""
        sc = self.load()
        spec = model_spec(sc, self.setup, _imported(self, sc))
        if self.sumo is None:
            yield spec
            return
        with tempfile.TemporaryDirectory(prefix="hiyari-road-") as tmp:
            net = spec.road.net or import_road(sc, Path(tmp))
            road = sumo_road(sc, self.sumo, net, self.warmup, self.setup.max_duration)
            doc = {**spec.doc, "sumocfg": str(self.sumo.config), "warmup_s": self.warmup}
            yield replace(spec, road=road, warmup=self.warmup, doc=doc,
                          metadata={**spec.metadata, **doc})  # fmt: skip


@dataclass(frozen=True)
class XoscPlan:
    """The runs of an OpenSCENARIO scenario or distribution file (``path``, as given):
    ``param_sets`` the executed runs' values, ``indices`` their indices in the distribution
    (the skipped runs' indices are missing from it)."""

    path: str
    name: str
    scenario: Path
    param_sets: tuple[dict[str, str], ...]
    setup: EgoSetup
    road: Path
    road_net: tuple[Path, Path] | None = None
    indices: tuple[int, ...] | None = None  # None: 0, 1, ... (nothing skipped)
    skipped: tuple[SkippedRun, ...] = ()
    sumo: SumoScenario | None = None  # the user's SUMO scenario every run drives inside
    warmup: float = 0.0  # s the SUMO scenario's demand runs before the storyboard starts
    ego: str | None = None  # the ego entity's name (None: the reader picks it)

    @property
    def parameter_names(self) -> list[str]:
        """Every parameter any run sets, in first-seen order."""
        names: dict[str, None] = {}
        for p in (*self.param_sets, *(r.params for r in self.skipped)):
            names.update(dict.fromkeys(p))
        return list(names)

    @property
    def varied(self) -> list[str]:
        """Numeric parameters whose value differs between runs (the sweep plot's axes)."""
        out = []
        for k in self.parameter_names:
            vals = {p.get(k) for p in self.param_sets}
            if len(vals) > 1 and all(_is_number(v) for v in vals):
                out.append(k)
        return out

    def count(self) -> int:
        """Number of runs executed (the skipped ones are in ``skipped``)."""
        return len(self.param_sets)

    def expand(self) -> list[XoscRun]:
        """The concrete runs, run ``k`` of the distribution seeded ``setup.seed + k``."""
        indices = self.indices or range(len(self.param_sets))
        return [
            XoscRun(
                self.scenario,
                self.name,
                k,
                dict(p),
                replace(self.setup, seed=self.setup.seed + k),
                self.road_net,
                sumo=self.sumo,
                warmup=self.warmup,
                ego=self.ego,
            )
            for k, p in zip(indices, self.param_sets, strict=True)
        ]

    def with_roads(self, folder: Path) -> XoscPlan:
        """This plan with its road imported once into ``folder`` for every run (sweeps); a
        SUMO scenario the runs drive inside is checked against it here, before any run."""
        sc = read_scenario(self.scenario, self.param_sets[0], self.ego)
        net = import_road(sc, folder)
        if self.sumo is not None:
            sumo_road(sc, self.sumo, net, self.warmup, self.setup.max_duration)
        return replace(self, road_net=(self.road, net))


def _is_number(v: str | None) -> bool:
    try:
        float(v)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False
    return True


def is_openscenario(path: str | Path) -> bool:
    """Whether ``path`` names an OpenSCENARIO file (by its extension)."""
    return Path(path).suffix.lower() == ".xosc"


def load_plan(
    path: str | Path,
    setup: EgoSetup | None = None,
    params: Mapping[str, str] | None = None,
    sumo: SumoScenario | None = None,
    warmup: float = 0.0,
    ego: str | None = None,
) -> XoscPlan:
    """The runs of the scenario or distribution file ``path``, checked (see module).

    ``params``: values for the scenario's top-level ParameterDeclarations in every run (as
    esmini's ``--param``), checked like the file's own: a declared name, its type and its
    ValueConstraints; a distribution may not set them too. ``sumo``: run inside this SUMO
    scenario (its net must be the conversion of the scenario's road: ``sumo_road``), its
    demand running ``warmup`` s before the storyboard starts. ``ego``: the entity the ego stack
    drives (None: the reader's choice; a scenario with none is refused)."""
    setup = setup or EgoSetup()
    params = dict(params or {})
    root = document.load(path)
    if root.find("ParameterValueDistribution") is not None:
        dist = read_distribution(path, setup.seed)
        scenario, sets = dist.scenario, dist.runs
        both = sorted({k for s in sets for k in s} & set(params))
        if both:
            raise HiyariError(
                f"{path}: --param {', '.join(both)}: the distribution sets it (one or the other)"
            )
    else:
        scenario, sets = Path(path).resolve(), ({},)
    if not sets:
        raise HiyariError(f"{path}: the distribution gives no run")
    _check_integers(scenario, params)
    sets = tuple({**s, **params} for s in sets)
    kept, skipped = _constrained(scenario, sets, setup.seed)
    if not kept and len(sets) == 1:
        raise skipped[0][1]  # a single scenario: its values are simply wrong
    if not kept:
        first = skipped[0][0]
        raise HiyariError(
            f"{path}: every run breaks the scenario's ConstraintGroups, nothing to run "
            f"({len(sets)} runs, {len(sets)} skipped: constraint; run #{first.index}: "
            f"{first.reason})"
        )
    first = read_scenario(scenario, sets[kept[0]], ego)
    if first.ego is None:
        raise HiyariError(no_ego(first))
    if first.road_network is None:
        raise HiyariError(f"{scenario}: <RoadNetwork> names no <LogicFile> (OpenDRIVE road)")
    return XoscPlan(
        str(path),
        scenario.stem,
        scenario,
        tuple(sets[k] for k in kept),
        setup,
        first.road_network,
        indices=tuple(kept),
        skipped=tuple(s for s, _ in skipped),
        sumo=sumo,
        warmup=warmup,
        ego=ego,
    )


def _constrained(
    scenario: Path, sets: tuple[dict[str, str], ...], seed: int
) -> tuple[list[int], list[tuple[SkippedRun, ConstraintViolation]]]:
    """The indices of the runs whose values fit the scenario's ConstraintGroups, and the
    others as skipped runs. Only the top-level ParameterDeclarations are evaluated (entering
    the root reads nothing else), what read_scenario does first: a run costs its
    declarations, not a read of the scenario."""
    root = document.load(scenario)
    kept, skipped = [], []
    for k, values in enumerate(sets):
        try:
            Ctx(scenario, Scope()).enter(root, values)
        except ConstraintViolation as exc:
            run = SkippedRun(k, seed + k, dict(values), exc.detail(), scenario.stem)
            skipped.append((run, exc))
            continue
        kept.append(k)
    return kept, skipped


def _check_integers(scenario: Path, params: Mapping[str, str]) -> None:
    """Integer parameters set by hand must be given as integers (the reader rounds a
    computed value, as OpenSCENARIO converts a double to an int; a typed 1.5 is a mistake)."""
    decls = document.load(scenario).find("ParameterDeclarations") if params else None
    for d in [] if decls is None else decls.findall("ParameterDeclaration"):
        name, ptype = d.get("name"), d.get("parameterType")
        if name in params and ptype in INT_TYPES:
            try:
                whole = float(params[name]).is_integer()
            except ValueError:
                continue  # not a number at all: the reader says so
            if not whole:
                raise HiyariError(
                    f"{scenario}:{d.sourceline}: --param {name}={params[name]}: "
                    f"the parameter is an {ptype}"
                )


def _imported(run: XoscRun, sc: Scenario) -> Path | None:
    """The SUMO net already imported for the scenario's road (None: import it)."""
    if run.road_net is not None and sc.road_network == run.road_net[0]:
        return run.road_net[1] if run.road_net[1].is_file() else None
    return None
