"""``hiyari perception coverage``: principle coverage per sensor and merged, as files."""

from __future__ import annotations

from pathlib import Path

from hiyari.atomic import write_text_atomic
from hiyari.bridge.studies.report.perception.coverage import coverage_figure
from hiyari.errors import HiyariError
from hiyari.sensors.coverage.coverage import merged_list, principle_coverage
from hiyari.sensors.coverage.disturbances import load_disturbances
from hiyari.sensors.coverage.matrices import SENSORS, load_matrices
from hiyari.sensors.coverage.report import coverage_markdown


def parse_sensors(text: str) -> tuple[str, ...]:
    """'camera,radar,lidar' -> ('camera', 'radar', 'lidar'); HiyariError on unknown names."""
    names = tuple(dict.fromkeys(s.strip() for s in text.split(",") if s.strip()))
    bad = [s for s in names if s not in SENSORS]
    if bad or not names:
        raise HiyariError(f"--sensors: unknown sensor(s) {bad} (known: {', '.join(SENSORS)})")
    return names


def write_coverage(sensors: tuple[str, ...], out_dir: Path) -> tuple[str, dict[str, Path]]:
    """Compute coverage for ``sensors``; write coverage.md and coverage.png into ``out_dir``.
    Returns the Markdown and the paths."""
    matrices = load_matrices(sensors)
    registry = load_disturbances()
    per = {s: principle_coverage(m, registry) for s, m in matrices.items()}
    merged = merged_list(matrices, registry)
    text = coverage_markdown(per, merged)
    out_dir.mkdir(parents=True, exist_ok=True)
    md = write_text_atomic(out_dir / "coverage.md", text)
    names = [d.name for d in registry.disturbances if any(s in d.sensors for s in sensors)]
    png = coverage_figure(per, names, out_dir / "coverage.png")
    return text, {"md": md, "png": png}
