"""The SCT sensitivity study's outputs: sensitivity.csv and one panel per varied parameter."""

from __future__ import annotations

import csv
import math
from dataclasses import asdict
from pathlib import Path

from matplotlib.figure import Figure

from hiyari.atomic import atomic_path
from hiyari.bridge.studies.sct.sensitivity import PARAMETERS, SensitivityPoint
from hiyari.bridge.studies.sct.summary import SEED_REDUCTION


def write_sensitivity(folder: str | Path, points: list[SensitivityPoint], hours: float) -> Path:
    """``sensitivity.csv`` and ``sensitivity.png`` (reduction against each parameter, the
    seed's reduction as a line) in ``folder``; returns the PNG's path."""
    folder = Path(folder)
    with atomic_path(folder / "sensitivity.csv") as tmp, tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(asdict(points[0])))
        w.writeheader()
        for pt in points:
            w.writerow(asdict(pt))
    fig = Figure(figsize=(12, 3.8))
    axes = fig.subplots(1, len(PARAMETERS), sharey=True)
    for ax, (param, label) in zip(axes, PARAMETERS.items(), strict=True):
        pts = [pt for pt in points if pt.parameter == param]
        x = [pt.value for pt in pts]
        y = [-100 * pt.reduction for pt in pts]
        ax.plot(x, y, "o-", color="#2a7", lw=2, label="hiyari (SUMO)")
        for pt, yy in zip(pts, y, strict=True):
            if not math.isnan(yy):
                ax.annotate(
                    f"{pt.baseline_incidents}→{pt.sct_incidents}",
                    (pt.value, yy),
                    textcoords="offset points",
                    xytext=(0, 7),
                    ha="center",
                    fontsize=8,
                )
        ax.axhline(-100 * SEED_REDUCTION, color="#c33", ls="--", lw=1.2, label="DIVP seed −68 %")
        ax.set_xlabel(label)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("incident change, SCT vs baseline, %")
    top = max([0.0, *(-100 * p.reduction for p in points if not math.isnan(p.reduction))])
    axes[0].set_ylim(-100, top + 10)
    axes[0].legend(loc="lower right", fontsize=8)
    fig.suptitle(
        f"Sensitivity of the incident reduction ({hours:g} simulated h per arm and point; "
        "labels: baseline → SCT incidents)"
    )
    with atomic_path(folder / "sensitivity.png") as tmp:
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    return folder / "sensitivity.png"
