"""Scenario files (TOML): a logical scenario with parameter ranges -> concrete scenarios.

Layers as the JAMA / DIVP scenario descriptions use them: the *logical* scenario names a
scenario type and ranges for its parameters; expanding it gives *concrete* scenarios, one value
per parameter, each run once. A file::

    [scenario]
    type = "cut-in"          # cut-in | cut-out | decel | dart-out | stationary | city
    name = "R157 cut-in grid"
    seed = 1                 # base seed; concrete run k uses seed + k
    duration = 20.0          # simulated seconds (optional; type default otherwise)

    [ego]
    perception = "perfect"   # perfect | sensors | none
    sensors = ["camera", "radar", "lidar"]   # used when perception = "sensors"
    aeb_delay = 0.2          # s, brake actuation delay

    [environment]
    preset = "clear"         # a disturbance preset (sensors/presets)

    [parameters]             # per scenario type, see PARAMETERS below
    ve0_kmh = 60
    vo0_kmh = { range = [20, 60], step = 10 }    # grid over a range
    vy_ms = { values = [0.5, 1.0, 2.0] }         # an explicit list
    dx0_m = { uniform = [5.0, 40.0] }            # random sampling (needs [sampling] n)

    [sampling]
    mode = "grid"            # grid: the product of every range and list; random: n draws
    n = 50                   # random mode only
    seed = 7                 # random mode only

Unknown sections or keys, missing parameters and impossible values raise HiyariError naming
the file and the key.
"""

from __future__ import annotations

import itertools
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiyari.errors import HiyariError

#: Parameters of each scenario type: name -> (default or None when required, (min, max)).
PARAMETERS: dict[str, dict[str, tuple[float | None, tuple[float, float]]]] = {
    "cut-in": {
        "ve0_kmh": (None, (1.0, 200.0)),
        "vo0_kmh": (None, (0.0, 200.0)),
        "dx0_m": (None, (-10.0, 500.0)),
        "vy_ms": (None, (0.01, 5.0)),
    },
    "cut-out": {
        "ve0_kmh": (None, (1.0, 200.0)),
        "vy_ms": (None, (0.01, 5.0)),
        "dx0_f_m": (None, (0.0, 500.0)),
    },
    "decel": {
        "ve0_kmh": (None, (1.0, 200.0)),
        "gx_max_g": (None, (0.01, 1.5)),
    },
    "dart-out": {
        "ve0_kmh": (40.0, (1.0, 100.0)),
        "ped_speed_kmh": (5.0, (1.0, 25.0)),
        "impact_fraction": (0.5, (0.0, 1.0)),
        "parked_car": (1.0, (0.0, 1.0)),  # 1: the child steps out from behind a parked car
    },
    "stationary": {
        "ve0_kmh": (50.0, (1.0, 200.0)),
        "gap_m": (150.0, (10.0, 1000.0)),
    },
    "city": {
        "vehicles_per_hour": (1800.0, (0.0, 20000.0)),
        "persons_per_hour": (1800.0, (0.0, 20000.0)),
        "ve0_kmh": (40.0, (1.0, 100.0)),
        "warmup_s": (300.0, (0.0, 7200.0)),
    },
}

DEFAULT_DURATION = {
    "cut-in": 20.0,
    "cut-out": 25.0,
    "decel": 25.0,
    "dart-out": 15.0,
    "stationary": 30.0,
    "city": 120.0,
}
PERCEPTION_MODES = ("perfect", "sensors", "none")
SENSOR_NAMES = ("camera", "radar", "lidar")

_SECTIONS = {
    "scenario": {"type", "name", "seed", "duration", "step_length"},
    "ego": {"perception", "sensors", "aeb_delay", "stack"},
    "environment": {"preset"},
    "parameters": None,  # checked per scenario type
    "sampling": {"mode", "n", "seed"},
}


class Steps(Sequence[float]):
    """``lo, lo + step, ...`` (``n`` values, rounded to 1e-9): a range axis held as its three
    numbers, so that a tiny step is counted (and refused by a run-count guard) without ever
    being listed."""

    def __init__(self, lo: float, step: float, n: int) -> None:
        self.lo, self.step, self.n = lo, step, n

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, i):  # noqa: ANN001, ANN204 - Sequence protocol (int or slice)
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(self.n))]
        k = range(self.n)[i]
        return round(self.lo + k * self.step, 9)


@dataclass(frozen=True)
class ConcreteScenario:
    """One run: every parameter has a value. Speeds in the units their names give."""

    type: str
    name: str
    index: int
    seed: int
    duration: float
    step_length: float
    params: dict[str, float]
    perception: str = "perfect"
    sensors: tuple[str, ...] = SENSOR_NAMES
    aeb_delay: float = 0.2
    environment: str = "clear"
    stack: str = ""  # "module:callable" stack factory (called with a StackContext), '' default

    def label(self) -> str:
        """Short human-readable id, e.g. 'cut-in#3 ve0_kmh=60 vo0_kmh=20'."""
        vals = " ".join(f"{k}={v:g}" for k, v in self.params.items())
        return f"{self.type}#{self.index} {vals}"


@dataclass(frozen=True)
class LogicalScenario:
    """A scenario type with fixed values and parameter ranges, read from a file."""

    path: str
    type: str
    name: str
    seed: int
    duration: float
    step_length: float
    fixed: dict[str, float]
    ranges: dict[str, Sequence[float]]  # grid axes (Steps for range/step, or values)
    random: dict[str, tuple[float, float]]  # uniform draws
    sampling: dict[str, Any] = field(default_factory=dict)
    ego: dict[str, Any] = field(default_factory=dict)
    environment: str = "clear"

    def expand(self) -> list[ConcreteScenario]:
        """Concrete scenarios: the grid product, or ``sampling.n`` seeded random draws."""
        rows: list[dict[str, float]]
        if self.sampling.get("mode", "grid") == "random":
            n = int(self.sampling.get("n", 0))
            rng = np.random.default_rng(int(self.sampling.get("seed", self.seed)))
            rows = []
            for _ in range(n):
                row = dict(self.fixed)
                for k, vals in self.ranges.items():
                    row[k] = float(vals[rng.integers(len(vals))])
                for k, (lo, hi) in self.random.items():
                    row[k] = float(rng.uniform(lo, hi))
                rows.append(row)
        else:
            keys = list(self.ranges)
            rows = [
                {**self.fixed, **dict(zip(keys, combo, strict=True))}
                for combo in itertools.product(*(self.ranges[k] for k in keys))
            ]
        order = list(PARAMETERS[self.type])
        return [
            ConcreteScenario(
                type=self.type,
                name=self.name,
                index=i,
                seed=self.seed + i,
                duration=self.duration,
                step_length=self.step_length,
                params={k: row[k] for k in order},
                perception=self.ego.get("perception", "perfect"),
                sensors=tuple(self.ego.get("sensors", SENSOR_NAMES)),
                aeb_delay=float(self.ego.get("aeb_delay", 0.2)),
                environment=self.environment,
                stack=self.ego.get("stack", ""),
            )
            for i, row in enumerate(rows)
        ]


def _err(path: str, key: str, problem: str) -> HiyariError:
    return HiyariError(f"{path}: {key}: {problem}")


def _number(path: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _err(path, key, f"expected a number, got {value!r}")
    if not np.isfinite(value):  # TOML has inf and nan
        raise _err(path, key, f"expected a finite number, got {value!r}")
    return float(value)


def parse_scenario(data: dict[str, Any], path: str = "<scenario>") -> LogicalScenario:
    """Validate a parsed TOML document and build the LogicalScenario."""
    _check_sections(data, path)
    sc = data.get("scenario")
    if sc is None or "type" not in sc:
        raise _err(path, "scenario.type", "missing")
    stype = sc["type"]
    if stype not in PARAMETERS:
        raise _err(
            path, "scenario.type", f"unknown type {stype!r} (known: {', '.join(PARAMETERS)})"
        )
    seed = sc.get("seed", 1)
    if not isinstance(seed, int) or seed < 0:
        raise _err(path, "scenario.seed", f"expected a non-negative integer, got {seed!r}")
    duration = _number(path, "scenario.duration", sc.get("duration", DEFAULT_DURATION[stype]))
    step = _number(path, "scenario.step_length", sc.get("step_length", 0.05))
    if duration <= 0:
        raise _err(path, "scenario.duration", f"must be positive, got {duration}")
    if not 0.001 <= step <= 0.5:
        raise _err(path, "scenario.step_length", f"must be within 0.001..0.5 s, got {step}")
    fixed, ranges, rand = _parameters(data.get("parameters", {}), stype, path)
    sampling = _sampling(dict(data.get("sampling", {})), bool(rand), path)
    ego = _ego(dict(data.get("ego", {})), path)
    env = data.get("environment", {}).get("preset", "clear")
    return LogicalScenario(
        path=path,
        type=stype,
        name=str(sc.get("name", stype)),
        seed=seed,
        duration=duration,
        step_length=step,
        fixed=fixed,
        ranges=ranges,
        random=rand,
        sampling=sampling,
        ego=ego,
        environment=env,
    )


def _check_sections(data: dict[str, Any], path: str) -> None:
    for section in data:
        if section not in _SECTIONS:
            raise _err(path, section, f"unknown section (known: {', '.join(_SECTIONS)})")
        if not isinstance(data[section], dict):
            raise _err(path, section, "must be a table")
        allowed = _SECTIONS[section]
        for key in data[section]:
            if allowed is not None and key not in allowed:
                raise _err(
                    path, f"{section}.{key}", f"unknown key (known: {', '.join(sorted(allowed))})"
                )


def _parameters(
    given: dict[str, Any], stype: str, path: str
) -> tuple[dict[str, float], dict[str, Sequence[float]], dict[str, tuple[float, float]]]:
    """Fixed values, swept axes and random ranges of a type's parameters, checked."""
    spec = PARAMETERS[stype]
    fixed: dict[str, float] = {}
    ranges: dict[str, Sequence[float]] = {}
    rand: dict[str, tuple[float, float]] = {}
    for key in given:
        if key not in spec:
            raise _err(path, f"parameters.{key}", f"unknown for {stype} (known: {', '.join(spec)})")
    for key, (default, (lo, hi)) in spec.items():
        k = f"parameters.{key}"
        value = given.get(key, default)
        if value is None:
            raise _err(path, k, f"missing (required for {stype})")
        if isinstance(value, dict):
            vals = _axis(path, k, value, rand, key)
            ends = (vals[0], vals[-1]) if isinstance(vals, Steps) else vals
            for v in ends if vals is not None else rand[key]:
                _check_range(path, k, v, lo, hi)
            if vals is not None:
                ranges[key] = vals
        else:
            fixed[key] = _check_range(path, k, _number(path, k, value), lo, hi)
    return fixed, ranges, rand


def _sampling(sampling: dict[str, Any], has_random: bool, path: str) -> dict[str, Any]:
    mode = sampling.get("mode", "grid")
    if mode not in ("grid", "random"):
        raise _err(path, "sampling.mode", f"must be grid or random, got {mode!r}")
    if has_random and mode != "random":
        raise _err(path, "sampling.mode", 'uniform ranges need mode = "random" and n')
    if mode == "random":
        n = sampling.get("n")
        if not isinstance(n, int) or n < 1:
            raise _err(path, "sampling.n", f"expected a positive integer, got {n!r}")
    return sampling


def _ego(ego: dict[str, Any], path: str) -> dict[str, Any]:
    perception = ego.get("perception", "perfect")
    if perception not in PERCEPTION_MODES:
        raise _err(
            path, "ego.perception", f"unknown {perception!r} (known: {', '.join(PERCEPTION_MODES)})"
        )
    for s in ego.get("sensors", SENSOR_NAMES):
        if s not in SENSOR_NAMES:
            raise _err(
                path, "ego.sensors", f"unknown sensor {s!r} (known: {', '.join(SENSOR_NAMES)})"
            )
    if "aeb_delay" in ego:
        d = _number(path, "ego.aeb_delay", ego["aeb_delay"])
        if not 0 <= d <= 3:
            raise _err(path, "ego.aeb_delay", f"must be within 0..3 s, got {d}")
    return ego


def _axis(path: str, k: str, value: dict, rand: dict, key: str) -> Sequence[float] | None:
    if set(value) == {"values"}:
        vals = value["values"]
        if not isinstance(vals, list) or not vals:
            raise _err(path, k, "values must be a non-empty list")
        return [_number(path, k, v) for v in vals]
    if set(value) == {"range", "step"}:
        r, step = value["range"], _number(path, k, value["step"])
        if not (isinstance(r, list) and len(r) == 2) or step <= 0:
            raise _err(path, k, "range must be [lo, hi] with a positive step")
        lo, hi = _number(path, k, r[0]), _number(path, k, r[1])
        if hi < lo:
            raise _err(path, k, f"range [{lo}, {hi}] is empty")
        count = np.floor((hi - lo) / step + 1e-9) + 1
        if not count < 2**53:  # also catches an overflow to inf
            raise _err(
                path, k, f"range [{lo:g}, {hi:g}] in steps of {step:g} gives {count:.3g} values"
            )
        return Steps(lo, step, int(count))
    if set(value) == {"uniform"}:
        r = value["uniform"]
        if not (isinstance(r, list) and len(r) == 2):
            raise _err(path, k, "uniform must be [lo, hi]")
        lo, hi = _number(path, k, r[0]), _number(path, k, r[1])
        if hi < lo:
            raise _err(path, k, f"uniform [{lo}, {hi}] is empty")
        rand[key] = (lo, hi)
        return None
    raise _err(
        path,
        k,
        "expected a number, {values = [...]}, {range = [lo, hi], step = s} or {uniform = [lo, hi]}",
    )


def _check_range(path: str, key: str, v: float, lo: float, hi: float) -> float:
    if not lo <= v <= hi:
        raise _err(path, key, f"{v:g} is outside {lo:g}..{hi:g}")
    return v


def load_scenario(path: str | Path) -> LogicalScenario:
    """Read and validate a scenario file."""
    p = Path(path)
    if not p.is_file():
        raise HiyariError(f"{p}: scenario file not found")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise HiyariError(f"{p}: not UTF-8 text (byte {exc.start})") from None
    except tomllib.TOMLDecodeError as exc:
        raise HiyariError(f"{p}: not valid TOML: {exc}") from None
    return parse_scenario(data, str(p))
