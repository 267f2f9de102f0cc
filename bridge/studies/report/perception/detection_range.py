"""The detection-range table written out: Markdown, CSV and a bar chart per target."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from hiyari.atomic import atomic_path
from hiyari.sensors.detection_range import SENSORS, table_markdown


def write_table(rows: list[dict], out_dir: str | Path) -> dict[str, Path]:
    """Write perception_table.md, .csv and .png into ``out_dir``; returns the paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {
        "md": out / "perception_table.md",
        "csv": out / "perception_table.csv",
        "png": out / "perception_table.png",
    }
    with atomic_path(paths["md"]) as tmp:
        tmp.write_text(
            "Detection range (m) per sensor and disturbance preset\n\n" + table_markdown(rows)
        )
    with atomic_path(paths["csv"]) as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    targets = list(dict.fromkeys(r["target"] for r in rows))
    presets = list(dict.fromkeys(r["preset"] for r in rows))
    fig = Figure(figsize=(6 * len(targets), 4.5))
    axes = fig.subplots(1, len(targets), sharey=True)
    for ax, t in zip(np.atleast_1d(axes), targets, strict=True):
        x = np.arange(len(presets))
        for k, s in enumerate(SENSORS):
            vals = [
                next(r[f"{s}_m"] for r in rows if r["target"] == t and r["preset"] == p)
                for p in presets
            ]
            ax.bar(x + (k - 1) * 0.27, vals, 0.27, label=s)
        ax.set_xticks(x, presets, rotation=45, ha="right")
        ax.set_title(f"{t} target")
        ax.grid(axis="y", alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("detection range (m)")
    np.atleast_1d(axes)[0].legend()
    fig.suptitle("hiyari: detection range per sensor under JAMA perception disturbances")
    fig.tight_layout()
    with atomic_path(paths["png"]) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return paths
