"""``hiyari perception sweep``: the representative disturbances (or named ones) swept."""

from __future__ import annotations

from pathlib import Path

from hiyari.bridge.studies.perception.sweep import SweepConfig, SweepRow, levels, sweep_disturbance
from hiyari.bridge.studies.report.perception_sweep import write_sweep
from hiyari.sensors.coverage.coverage import principle_coverage, representatives
from hiyari.sensors.coverage.disturbances import load_disturbances
from hiyari.sensors.coverage.matrices import load_matrices


def run_sweep(
    names: list[str] | None, cfg: SweepConfig, out_dir: Path, progress: bool = True
) -> tuple[list[SweepRow], dict[str, Path]]:
    """Sweep ``names`` (default: the representative set of the camera + radar + LiDAR
    coverage) and write the results into ``out_dir``."""
    from tqdm import tqdm

    reg = load_disturbances()
    if not names:
        per = {s: principle_coverage(m, reg) for s, m in load_matrices().items()}
        swept = tuple(d.name for d in reg.disturbances if d.kind == "target")
        names = representatives(per, exclude=swept)
    chosen = [reg.get(n) for n in names]
    rows: list[SweepRow] = []
    with tqdm(
        total=sum(len(levels(d, cfg.levels)) for d in chosen) * len(cfg.targets),
        desc="perception sweep",
        disable=not progress,
    ) as bar:
        for d in chosen:
            rows += sweep_disturbance(d, cfg, progress=bar)
    return rows, write_sweep(rows, out_dir)
