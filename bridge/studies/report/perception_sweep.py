"""Sweep results as CSV, Markdown and a PNG of detection range against intensity."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from hiyari.atomic import atomic_path, write_text_atomic
from hiyari.bridge.studies.perception.sweep import OUTPUTS, SweepRow
from hiyari.sensors.detection_range import SENSORS


def _flat(r: SweepRow) -> dict:
    out = {"disturbance": r.disturbance, "level": r.level, "unit": r.unit, "target": r.target}
    for o in OUTPUTS:
        out[f"{o}_range_m"] = r.range_m[o]
        out[f"{o}_missed"] = r.missed[o]
        out[f"{o}_ghosts"] = r.ghosts[o]
    return out


def _pct(x: float) -> str:
    return "-" if math.isnan(x) else f"{100 * x:.0f}"


def sweep_markdown(rows: list[SweepRow]) -> str:
    """One line per disturbance level and target: range (m) / missed % / ghost % per output."""
    head = "| disturbance | level | target | " + " | ".join(OUTPUTS) + " |"
    lines = [
        "# Representative-factor sweep: detection range m / missed % / ghost %",
        "",
        "Missed: frames without the target inside that output's clear-level range; ghosts:",
        "frames with a false object (no real surface behind it).",
        "",
        head,
        "|---|---:|---|" + "---:|" * len(OUTPUTS),
    ]
    for r in rows:
        cells = [f"{r.range_m[o]:.0f} / {_pct(r.missed[o])} / {_pct(r.ghosts[o])}" for o in OUTPUTS]
        lines.append(
            f"| {r.disturbance} | {r.level:.4g} ({r.unit}) | {r.target} | "
            + " | ".join(cells)
            + " |"
        )
    return "\n".join(lines) + "\n"


def write_sweep(rows: list[SweepRow], out_dir: Path) -> dict[str, Path]:
    """sweep.csv, sweep.md and sweep.png in ``out_dir``."""
    from matplotlib.figure import Figure

    out_dir.mkdir(parents=True, exist_ok=True)
    paths = {"csv": out_dir / "sweep.csv", "md": out_dir / "sweep.md", "png": out_dir / "sweep.png"}
    flat = [_flat(r) for r in rows]
    with atomic_path(paths["csv"]) as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(flat[0]))
        w.writeheader()
        w.writerows(flat)
    write_text_atomic(paths["md"], sweep_markdown(rows))
    names = list(dict.fromkeys(r.disturbance for r in rows))
    targets = list(dict.fromkeys(r.target for r in rows))
    fig = Figure(figsize=(3.2 * len(targets), 2.3 * len(names) + 0.8))
    axes = np.atleast_2d(fig.subplots(len(names), len(targets), squeeze=False))
    for i, name in enumerate(names):
        for j, target in enumerate(targets):
            ax = axes[i, j]
            sel = [r for r in rows if r.disturbance == name and r.target == target]
            x = np.arange(len(sel))
            # the fused line wide and pale underneath, so a sensor on the same values shows
            ax.plot(
                x, [r.range_m["fused"] for r in sel], color="0.6", lw=6, alpha=0.5, label="fused"
            )
            for o in SENSORS:
                ax.plot(x, [r.range_m[o] for r in sel], marker="o", label=o)
            ax.set_xticks(x, [f"{r.level:.4g}" for r in sel], fontsize=7)
            ax.grid(alpha=0.3)
            if i == 0:
                ax.set_title(target, fontsize=9)
            if j == 0:
                ax.set_ylabel(f"{name}\nrange (m)", fontsize=8)
            if i == len(names) - 1:
                ax.set_xlabel("intensity (clear -> severe)", fontsize=7)
        axes[i, -1].annotate(
            sel[0].unit, (1.02, 0.5), xycoords="axes fraction", fontsize=6, rotation=90, va="center"
        )
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(
        "hiyari: detection range per sensor and fused, representative JAMA factors", fontsize=10
    )
    fig.tight_layout(rect=(0, 0, 1, 0.98))
    with atomic_path(paths["png"]) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    return paths
