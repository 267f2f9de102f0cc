"""Figures of the safety-argument report: the catalogue matrix and per-combination datasheets
(matplotlib Figure objects, no pyplot; the caller saves them)."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

from hiyari.bridge.studies.catalogue.space.obstruction import Cell
from hiyari.units import mps_to_kmh

#: A cell is green only when every run passed; one failure makes it red (a pass rate shaded
#: between the two read as "mostly passed", which a failure is not).
PASSED = "#2e7d32"
FAILED = "#c62828"
NOT_APPLICABLE = "#e0e0e0"
NOT_RUN = "#ffffff"


def row_label(cell: Cell) -> str:
    c = cell.combination
    chain = "chain §4.1.3: " if c.prefix == "C" else ""
    return f"{chain}{c.geometry.value} / ego {c.ego.value}"


def col_label(cell: Cell) -> str:
    return f"{cell.combination.motion.value}\n{cell.position.value}"


def matrix_layout(cells: list[Cell]) -> tuple[list[str], list[str]]:
    """Row and column labels in catalogue order (rows: geometry x ego motion; columns:
    surrounding motion x position)."""
    rows: list[str] = []
    cols: list[tuple[int, int, str]] = []
    motions = list(dict.fromkeys(c.combination.motion for c in cells))
    positions = list(dict.fromkeys(c.position for c in cells))
    for c in cells:
        if row_label(c) not in rows:
            rows.append(row_label(c))
        key = (motions.index(c.combination.motion), positions.index(c.position), col_label(c))
        if key not in cols:
            cols.append(key)
    return rows, [k[2] for k in sorted(cols)]


def matrix_figure(cells: list[Cell], stats: dict[str, tuple[int, int]]) -> Figure:
    """The catalogue matrix: each (row, column) over its lane counts green when every run
    passed, red when one failed, with "passed/run"; grey: not applicable; white: applicable
    but not run.
    ``stats``: cell key -> (passed, runs)."""
    rows, cols = matrix_layout(cells)
    passed = np.zeros((len(rows), len(cols)))
    runs = np.zeros((len(rows), len(cols)))
    valid = np.zeros((len(rows), len(cols)), bool)
    for c in cells:
        i, j = rows.index(row_label(c)), cols.index(col_label(c))
        valid[i, j] |= c.valid
        p, n = stats.get(c.key, (0, 0))
        passed[i, j] += p
        runs[i, j] += n
    height = 0.5 * len(rows) + 1.6
    fig = Figure(figsize=(max(10.0, 0.55 * len(cols) + 3.0), height), dpi=110)
    ax = fig.add_axes((0.16, 0.02, 0.83, 1 - 1.45 / height))
    rgba = np.ones((len(rows), len(cols), 4))
    rgba[(runs > 0) & (passed == runs)] = to_rgba(PASSED)
    rgba[(runs > 0) & (passed < runs)] = to_rgba(FAILED)
    rgba[~valid] = to_rgba(NOT_APPLICABLE)
    ax.imshow(rgba, aspect="auto", interpolation="nearest")
    for i in range(len(rows)):
        for j in range(len(cols)):
            if runs[i, j] > 0:
                text, colour = f"{int(passed[i, j])}/{int(runs[i, j])}", "white"
            else:
                text, colour = ("–" if not valid[i, j] else "not run"), "#555555"
            ax.text(j, i, text, ha="center", va="center", fontsize=7, color=colour)
    ax.set_yticks(range(len(rows)), rows, fontsize=8)
    ax.set_xticks(range(len(cols)), cols, fontsize=7, rotation=90)
    ax.xaxis.tick_top()
    ax.set_xticks(np.arange(-0.5, len(cols)), minor=True)
    ax.set_yticks(np.arange(-0.5, len(rows)), minor=True)
    ax.grid(which="minor", color="white", linewidth=1.5)
    ax.tick_params(which="minor", length=0)
    fig.suptitle("JAMA traffic-disturbance catalogue: passed / concrete runs per cell (both "
                 "lane counts); green: all passed, red: a failure; grey –: not applicable",
                 fontsize=10, y=0.99)  # fmt: skip
    return fig


def _axes_values(rows: list[dict]) -> tuple[str, str]:
    """The two parameters a datasheet plots: ego speed and the gap-like one."""
    keys = list(rows[0]["_params"])
    second = next((k for k in ("gap", "lead_thw", "plus_one_gap") if k in keys), keys[-1])
    return "ego_speed", second


def datasheet_figure(
    title: str, groups: dict[str, list[dict]], limits: dict[str, tuple[float, float]]
) -> Figure:
    """One panel per cell of a combination: its concrete runs over ego speed (km/h) and the
    gap-like parameter; green: passed, red x: failed; hollow grey square: the C&C driver
    collides too (not Preventable). ``limits``: logical range per parameter (SI): the axes
    span them, so the sampled region reads at a glance."""
    n = len(groups)
    cols = min(n, 4)
    nrows = (n + cols - 1) // cols
    fig = Figure(figsize=(3.3 * cols, 2.8 * nrows + 0.6), dpi=100)
    fig.suptitle(title, fontsize=10)
    for k, (label, rows) in enumerate(groups.items()):
        ax = fig.add_subplot(nrows, cols, k + 1)
        xk, yk = _axes_values(rows)
        x = np.array([mps_to_kmh(r["_params"][xk]) for r in rows])
        y = np.array([r["_params"][yk] for r in rows])
        ok = np.array([r["passed"] == "True" for r in rows])
        unpreventable = np.array([r["preventable"] != "True" for r in rows])
        ax.scatter(x[unpreventable], y[unpreventable], s=70, facecolors="none",
                   edgecolors="#9e9e9e", marker="s", label="C&C collides")  # fmt: skip
        ax.scatter(x[ok], y[ok], s=18, c="#2e7d32", label="passed")
        ax.scatter(x[~ok], y[~ok], s=40, c="#c62828", marker="x", label="failed")
        ax.set_title(f"{label}: {ok.sum()}/{len(ok)} passed", fontsize=8)
        for key, setter, scale in ((xk, ax.set_xlim, mps_to_kmh), (yk, ax.set_ylim, float)):
            if key in limits:
                lo, hi = limits[key]
                pad = 0.05 * (hi - lo)
                setter(scale(lo - pad), scale(hi + pad))
        ax.set_xlabel("ego speed, km/h", fontsize=7)
        ax.set_ylabel(yk.replace("_", " ") + (", s" if yk.endswith("thw") else ", m"), fontsize=7)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
        if k == 0:
            ax.legend(fontsize=6, loc="best")
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    return fig
