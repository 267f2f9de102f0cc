"""The simulable perception disturbances and which JAMA factor rows each one stands for.

Read from data/disturbances.toml (or a file given by the caller): every disturbance names its
kind (how a run applies it), the swept intensity range and unit, the sensor models that
implement it, and the factor rows per sensor it represents. Rows no disturbance covers carry a
reason why they are not simulated.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from hiyari.errors import HiyariError
from hiyari.sensors.coverage.matrices import SENSORS, Factor

KINDS = (
    "environment",
    "sun",
    "window",
    "mount",
    "pitch",
    "multipath",
    "occluder",
    "clothing",
    "target",
)


@dataclass(frozen=True)
class Disturbance:
    """One simulable disturbance."""

    name: str
    kind: str
    parameter: str
    unit: str
    range: tuple[float, float]
    """Intensity from the clear end to the severe end, in ``unit``."""
    sensors: tuple[str, ...]
    """Sensor models that implement it."""
    factors: dict[str, tuple[int, ...]]
    """Factor rows it stands for, per sensor matrix."""
    levels: int | None = None
    """Number of distinct intensities (2 for an on / off disturbance), None for continuous."""


@dataclass(frozen=True)
class DisturbanceRegistry:
    """All disturbances plus the reasons for the rows none of them covers."""

    disturbances: tuple[Disturbance, ...]
    class_reasons: dict[str, str]
    row_reasons: dict[str, str]

    def get(self, name: str) -> Disturbance:
        """The disturbance called ``name``; HiyariError lists the known ones."""
        for d in self.disturbances:
            if d.name == name:
                return d
        known = ", ".join(d.name for d in self.disturbances)
        raise HiyariError(f"unknown disturbance {name!r} (known: {known})")

    def covering(self, factor: Factor) -> list[Disturbance]:
        """Disturbances whose sensor model implements ``factor`` (same sensor, listed row)."""
        return [
            d
            for d in self.disturbances
            if factor.sensor in d.sensors and factor.row in d.factors.get(factor.sensor, ())
        ]

    def reason(self, factor: Factor) -> str:
        """Why ``factor`` is not simulated (row entry, else its class entry)."""
        listed = [
            d.name for d in self.disturbances if factor.row in d.factors.get(factor.sensor, ())
        ]
        if listed:
            return f"{', '.join(listed)} not implemented in the {factor.sensor} model"
        return self.row_reasons.get(
            factor.key, self.class_reasons.get(factor.factor_class, "no model")
        )


def load_disturbances(path: Path | None = None) -> DisturbanceRegistry:
    """The registry from ``path`` (default: the package's data/disturbances.toml)."""
    src = path or resources.files("hiyari.sensors.coverage") / "data" / "disturbances.toml"
    try:
        data = tomllib.loads(src.read_text(encoding="utf-8"))
        out = []
        for d in data["disturbance"]:
            lo, hi = (float(v) for v in d["range"])
            dist = Disturbance(
                name=d["name"],
                kind=d["kind"],
                parameter=d["parameter"],
                unit=d["unit"],
                range=(lo, hi),
                sensors=tuple(d["sensors"]),
                factors={s: tuple(int(r) for r in rows) for s, rows in d["factors"].items()},
                levels=int(d["levels"]) if "levels" in d else None,
            )
            bad = [s for s in (*dist.sensors, *dist.factors) if s not in SENSORS]
            if dist.kind not in KINDS or bad:
                raise HiyariError(
                    f"{src}: disturbance {dist.name!r}: unknown kind {dist.kind!r} or sensor(s) {bad}"
                )
            out.append(dist)
        reasons = data.get("not_simulable", {})
        return DisturbanceRegistry(
            tuple(out), dict(reasons.get("class", {})), dict(reasons.get("row", {}))
        )
    except (KeyError, TypeError, ValueError, tomllib.TOMLDecodeError) as e:
        raise HiyariError(f"{src}: malformed disturbance registry ({e})") from None
