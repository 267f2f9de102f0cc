"""Which principle columns the simulable disturbances exercise, per sensor and merged.

A principle is covered when at least one of its factor rows is implemented by a disturbance
(jama-B 4.2.1.3: any factor of a column stands for the others). A multi-sensor system is
evaluated on the merged list (4.2.1.5): the union of the per-sensor rows.
"""

from __future__ import annotations

from dataclasses import dataclass

from hiyari.sensors.coverage.disturbances import DisturbanceRegistry
from hiyari.sensors.coverage.matrices import Matrix


@dataclass(frozen=True)
class PrincipleCoverage:
    """One principle column and what exercises it."""

    sensor: str
    principle: str
    name: str
    stage: str
    factors: int
    """Factor rows marked in this column."""
    disturbances: tuple[str, ...]
    """Simulated disturbances that exercise it (empty: not covered)."""
    ranges: tuple[str, ...]
    """'name: lo..hi unit' per covering disturbance."""
    reasons: tuple[str, ...]
    """Why its factor rows are not simulated, when none is."""

    @property
    def covered(self) -> bool:
        """At least one disturbance exercises it."""
        return bool(self.disturbances)


def principle_coverage(matrix: Matrix, registry: DisturbanceRegistry) -> list[PrincipleCoverage]:
    """Coverage of each principle column of ``matrix`` that factor rows name.

    The radar / LiDAR recognition-stage columns (detection, clustering, tracking,
    classification) carry no row marks here: every factor reaches them through "←".
    """
    out = []
    for p in matrix.principles:
        rows = [f for f in matrix.factors if p.id in f.principles]
        if not rows:
            continue
        by = {d.name: d for f in rows for d in registry.covering(f)}
        reasons = () if by else tuple(dict.fromkeys(registry.reason(f) for f in rows))
        out.append(
            PrincipleCoverage(
                sensor=matrix.sensor,
                principle=p.id,
                name=p.name,
                stage=p.stage,
                factors=len(rows),
                disturbances=tuple(by),
                ranges=tuple(
                    f"{d.name}: {d.range[0]:g}..{d.range[1]:g} {d.unit}" for d in by.values()
                ),
                reasons=reasons,
            )
        )
    return out


@dataclass(frozen=True)
class MergedRow:
    """One disturbance of the merged multi-sensor list."""

    disturbance: str
    range: str
    principles: dict[str, tuple[str, ...]]
    """Principle columns exercised, per sensor."""


def merged_list(matrices: dict[str, Matrix], registry: DisturbanceRegistry) -> list[MergedRow]:
    """The merged list: each disturbance with the principles it exercises in every sensor."""
    out = []
    for d in registry.disturbances:
        per = {}
        for s, m in matrices.items():
            if s not in d.sensors:
                continue
            rows = [f for f in m.factors if f.row in d.factors.get(s, ())]
            per[s] = tuple(dict.fromkeys(p for f in rows for p in f.principles))
        if any(per.values()):
            out.append(MergedRow(d.name, f"{d.range[0]:g}..{d.range[1]:g} {d.unit}", per))
    return out


def representatives(
    per_sensor: dict[str, list[PrincipleCoverage]], exclude: tuple[str, ...] = ()
) -> list[str]:
    """Fewest disturbances that together exercise every covered principle of every sensor
    (greedy set cover, ties in registry order): the representative factors of JAMA 4.2.1.3."""
    need = {
        (c.sensor, c.principle): set(c.disturbances) - set(exclude)
        for cov in per_sensor.values()
        for c in cov
    }
    need = {k: v for k, v in need.items() if v}
    order = list(dict.fromkeys(d for v in need.values() for d in sorted(v)))
    chosen: list[str] = []
    while need:
        best = max(order, key=lambda d: sum(d in v for v in need.values()))
        chosen.append(best)
        need = {k: v for k, v in need.items() if best not in v}
    return chosen
