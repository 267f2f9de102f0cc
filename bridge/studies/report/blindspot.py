"""The blind-spot catalogue as Markdown and as a matrix figure."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from hiyari.atomic import atomic_path, write_text_atomic
from hiyari.bridge.studies.perception.blindspot.catalogue import (
    Motion,
    combinations,
    occluder_cases,
)
from hiyari.bridge.studies.perception.blindspot.occlusion import HIDDEN_BELOW
from hiyari.bridge.studies.perception.blindspot.run import CaseResult


def _verdict(r: CaseResult) -> str:
    if r.crashed:
        return f"crashed ({r.crashed}; run again)"
    if r.collision is None:
        return "not run"
    if r.tested is False:
        return f"NOT TESTED ({r.untested_cause})"
    if r.collision:
        return "COLLISION"
    near = ", NEAR MISS" if r.near_misses else ""
    return (
        f"no collision, min TTC {r.min_ttc_s:.1f} s{near}"
        if math.isfinite(r.min_ttc_s)
        else f"no conflict{near}"
    )


def verdict_counts(results: list[CaseResult]) -> str:
    """One line: runs tested and not tested, collisions and near misses of the tested ones,
    false activations of all (cases with one, and their sum)."""
    run = [r for r in results if r.collision is not None]
    tested = [r for r in run if r.tested is not False]
    false = [r.false_activations or 0 for r in run]
    return (
        f"Closed loop: {len(run)} runs, {len(tested)} tested, {len(run) - len(tested)} not "
        f"tested; {sum(bool(r.collision) for r in tested)} collisions, "
        f"{sum(bool(r.near_misses) for r in tested)} near misses; false activations in "
        f"{sum(f > 0 for f in false)} of {len(run)} runs ({sum(false)} in all)."
    )


def catalogue_markdown(results: list[CaseResult]) -> str:
    """Counts, then one line per realisable combination."""
    allc = combinations()
    hidden = sum(r.hidden for r in results)
    lines = [
        "# Blind spots caused by surrounding vehicles (JAMA 4.2.2.1)",
        "",
        f"{len(occluder_cases())} occluder cases, {len(allc)} combinations, "
        f"{sum(c.realisable for c in allc)} realisable (seed: 64 / 42, Fig. 75 lost; see README).",
        f"Ray-cast check: {hidden} of {len(results)} run cases have the hidden car below "
        f"{100 * HIDDEN_BELOW:.0f} % of its clear-view LiDAR returns at the start.",
        "",
        verdict_counts(results),
        "",
        "| case | geometry | hidden-car start (m from slot centre) | LiDAR visible % | occluded | AEB stage | false activations | verdict |",
        "|---|---|---:|---:|---|---:|---:|---|",
    ]
    for r in results:
        stage = "-" if r.aeb_max_stage is None else str(r.aeb_max_stage)
        false = "-" if r.false_activations is None else str(r.false_activations)
        lines.append(
            f"| {r.combo.name} | {r.combo.geometry.value} | {r.shift_m:+.1f} | "
            f"{100 * r.visible_fraction:.0f} | {'yes' if r.hidden else 'no'} | {stage} | "
            f"{false} | {_verdict(r)} |"
        )
    return "\n".join(lines) + "\n"


def catalogue_figure(results: list[CaseResult], path: Path) -> Path:
    """PNG matrix: occluder-hidden pairs x motions; grey not realisable, green / orange run
    (hidden / visible at the start), red collision; text: min TTC."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch, Rectangle

    motions = list(Motion)
    pairs = [(o, h) for o, hs in occluder_cases().items() for h in hs]
    by = {(r.combo.occluder, r.combo.hidden, r.combo.motion): r for r in results}
    colours = {"n/a": "#dddddd", "hidden": "#66bb6a", "visible": "#ffb74d", "collision": "#e53935"}
    fig = Figure(figsize=(7.5, 0.32 * len(pairs) + 1.6))
    ax = fig.subplots()
    for i, (o, h) in enumerate(pairs):
        for j, m in enumerate(motions):
            r = by.get((o, h, m))
            key = (
                "n/a"
                if r is None
                else "collision"
                if r.collision
                else "hidden"
                if r.hidden
                else "visible"
            )
            ax.add_patch(Rectangle((j, i), 1, 1, fc=colours[key], ec="white"))
            if r is not None and r.min_ttc_s is not None and math.isfinite(r.min_ttc_s):
                ax.text(
                    j + 0.5, i + 0.5, f"{r.min_ttc_s:.1f}", ha="center", va="center", fontsize=6
                )
    ax.set_xlim(0, len(motions))
    ax.set_ylim(len(pairs), 0)
    ax.set_xticks(np.arange(len(motions)) + 0.5, [m.value for m in motions], fontsize=8)
    ax.set_yticks(
        np.arange(len(pairs)) + 0.5, [f"occluder {o} / hidden {h}" for o, h in pairs], fontsize=7
    )
    ax.legend(
        handles=[Patch(color=c, label=k) for k, c in colours.items()],
        fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.04), ncol=4,
    )  # fmt: skip
    ax.set_title("hiyari: blind-spot catalogue (numbers: min ground-truth TTC, s)", fontsize=9)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return path


def write_catalogue(results: list[CaseResult], out_dir: Path) -> dict[str, Path]:
    """blindspots.md and blindspots.png in ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    return {
        "md": write_text_atomic(out_dir / "blindspots.md", catalogue_markdown(results)),
        "png": catalogue_figure(results, out_dir / "blindspots.png"),
    }
