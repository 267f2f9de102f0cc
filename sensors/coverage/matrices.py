"""The JAMA factor x principle matrices as data: radar Table 4-23, LiDAR 4-24, camera 4-25..27.

Rows are perception-disturbance factors, columns occurrence principles (jama-B section 3,
jama-C sections 3-5). A factor row holds its effect marks as extracted (◎ large, 〇 medium,
△ small), its outcome (missed / false detection, camera also position error) and the principle
columns it acts through. The PDF extraction lost the column of each mark; the columns stored
here are those the digests infer (radar: checked against the printed totals row), and
``principles_complete`` says whether the row's list is complete.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from hiyari.errors import HiyariError

SENSORS = ("radar", "lidar", "camera")
EFFECTS = (
    "missed",
    "false",
    "false+missed",
    "position",
    "false+position",
    "none",
    "not_applicable",
)
_FILES = {
    "radar": ("radar_principles.csv", "radar_table_4_23.csv", "Table 4-23"),
    "lidar": ("lidar_principles.csv", "lidar_table_4_24.csv", "Table 4-24"),
    "camera": ("camera_principles.csv", "camera_table_4_25_to_4_27.csv", "Tables 4-25 to 4-27"),
}


@dataclass(frozen=True)
class Principle:
    """One occurrence-principle column."""

    id: str
    stage: str
    """'perception', 'processing' or 'recognition'."""
    group: str
    name_ja: str
    name: str
    model_parameters: str
    printed_total: int | None
    """The table's own count of factors under this column (radar only), None when not printed."""
    total_confirmed: bool
    """The digest confirms the printed total from the row meanings."""


@dataclass(frozen=True)
class Factor:
    """One factor row of a matrix."""

    sensor: str
    row: int
    factor_class: str
    """JAMA factor class key: a, b, c, d-1..d-3, e, f, g-1..g-4, h-1..h-3, j-1..j-3, k-1..k-4."""
    group: str
    name: str
    marks: str
    effect: str
    applicable_items: int | None
    """The table's count of principles for this factor (radar only)."""
    principles: tuple[str, ...]
    principles_complete: bool

    @property
    def key(self) -> str:
        """'sensor:row', the factor's id across the merged list."""
        return f"{self.sensor}:{self.row}"


@dataclass(frozen=True)
class Matrix:
    """One sensor's factor x principle matrix."""

    sensor: str
    table: str
    principles: tuple[Principle, ...]
    factors: tuple[Factor, ...]

    def principle(self, pid: str) -> Principle:
        """The column called ``pid``."""
        for p in self.principles:
            if p.id == pid:
                return p
        raise HiyariError(f"{self.table}: no principle column {pid!r}")

    def column_count(self, pid: str) -> int:
        """How many factor rows this matrix marks under column ``pid``."""
        return sum(pid in f.principles for f in self.factors)


def _rows(path: Path | resources.abc.Traversable) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def _int(text: str | None) -> int | None:
    return int(text) if text not in (None, "") else None


def load_matrix(sensor: str, data_dir: Path | None = None) -> Matrix:
    """The matrix of ``sensor`` ('radar', 'lidar' or 'camera') from the package data (or
    ``data_dir``); HiyariError naming the file on a malformed row."""
    if sensor not in _FILES:
        raise HiyariError(f"unknown sensor {sensor!r} (known: {', '.join(SENSORS)})")
    pfile, ffile, table = _FILES[sensor]
    base = data_dir or resources.files("hiyari.sensors.coverage") / "data"
    try:
        principles = tuple(
            Principle(
                id=r["id"],
                stage=r["stage"],
                group=r["group"],
                name_ja=r["principle_ja"],
                name=r["principle_en"],
                model_parameters=r["model_parameters"],
                printed_total=_int(r["printed_total"]),
                total_confirmed=r["total_confirmed"] == "yes",
            )
            for r in _rows(base / pfile)
        )
        ids = {p.id for p in principles}
        factors = []
        for r in _rows(base / ffile):
            f = Factor(
                sensor=sensor,
                row=int(r["row"]),
                factor_class=r["factor_class"],
                group=r["group"],
                name=r.get("factor_en") or "",
                marks=r["marks"],
                effect=r["effect"],
                applicable_items=_int(r.get("applicable_items")),
                principles=tuple(p for p in r["principles"].split(";") if p),
                principles_complete=r.get("principles_complete", "no") == "yes",
            )
            bad = [p for p in f.principles if p not in ids]
            if bad or f.effect not in EFFECTS:
                raise HiyariError(
                    f"{base / ffile}: row {f.row}: unknown principle(s) {bad} or effect {f.effect!r}"
                )
            factors.append(f)
    except (KeyError, ValueError, OSError) as e:
        raise HiyariError(f"{base / ffile}: unreadable matrix data ({e})") from None
    return Matrix(sensor, table, principles, tuple(factors))


def load_matrices(sensors: tuple[str, ...] = SENSORS) -> dict[str, Matrix]:
    """Matrices of several sensors, keyed by sensor."""
    return {s: load_matrix(s) for s in sensors}
