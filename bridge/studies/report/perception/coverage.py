"""The JAMA principle coverage as a figure: principles x disturbances per sensor."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from hiyari.atomic import atomic_path
from hiyari.sensors.coverage.coverage import PrincipleCoverage


def coverage_figure(
    per_sensor: dict[str, list[PrincipleCoverage]], disturbances: list[str], path: Path
) -> Path:
    """PNG: per sensor a grid of perception principles (rows) x disturbances (columns), a
    filled cell where the disturbance exercises the principle; uncovered rows in red."""
    heights = [max(len(c), 1) for c in per_sensor.values()]
    fig = Figure(figsize=(3.5 + 0.42 * len(disturbances), 1.2 + 0.26 * sum(heights)))
    axes = fig.subplots(len(per_sensor), 1, gridspec_kw={"height_ratios": heights})
    for ax, (sensor, cov) in zip(np.atleast_1d(axes), per_sensor.items(), strict=True):
        grid = np.array([[d in c.disturbances for d in disturbances] for c in cov], float)
        ax.imshow(grid, cmap="Greens", vmin=0, vmax=1.4, aspect="auto")
        ax.set_yticks(range(len(cov)), [f"{c.principle} {c.name[:44]}" for c in cov], fontsize=7)
        for tick, c in zip(ax.get_yticklabels(), cov, strict=True):
            tick.set_color("black" if c.covered else "firebrick")
        ax.set_xticks(range(len(disturbances)), disturbances, rotation=60, ha="right", fontsize=7)
        ax.set_xticks(np.arange(-0.5, len(disturbances)), minor=True)
        ax.set_yticks(np.arange(-0.5, len(cov)), minor=True)
        ax.grid(which="minor", color="0.85", lw=0.5)
        ax.tick_params(which="minor", length=0)
        n = sum(c.covered for c in cov)
        ax.set_title(
            f"{sensor}: {n}/{len(cov)} principles exercised (red: not simulated)", fontsize=9
        )
    fig.suptitle("hiyari: JAMA principle coverage by simulated disturbance", fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return path
