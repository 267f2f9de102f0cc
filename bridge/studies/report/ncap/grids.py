"""The datasheet's colour grid of one Euro NCAP scenario: test speed (rows) x overlap, impact
position or target speed (columns), one panel per lighting; each cell in its colour band with
the impact speed (km/h), a tick when avoided, 'NT' when not tested."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure
from matplotlib.patches import Patch, Rectangle

from hiyari.atomic import atomic_path
from hiyari.bridge.studies.ncap.protocols import NcapTest
from hiyari.bridge.studies.ncap.scoring import Colour, PointScore

#: Cell colours (RGB 0..1) of the bands, and of a point not tested.
RGB = {
    Colour.GREEN: (0 / 255, 153 / 255, 51 / 255),
    Colour.YELLOW: (255 / 255, 221 / 255, 51 / 255),
    Colour.ORANGE: (255 / 255, 153 / 255, 51 / 255),
    Colour.BROWN: (150 / 255, 75 / 255, 0 / 255),
    Colour.RED: (255 / 255, 51 / 255, 51 / 255),
}
NOT_TESTED_RGB = (0.75, 0.75, 0.75)


def _order(values: list[str]) -> list[str]:
    """Distinct values, numerically sorted when all are numbers (or '/'-joined numbers: the
    two-parameter columns), else in first-seen order."""
    seen = list(dict.fromkeys(values))
    try:
        return sorted(seen, key=lambda v: tuple(float(x) for x in v.split("/")))
    except ValueError:
        return seen


def _cell_text(test: NcapTest, row: dict, score: PointScore) -> str:
    if score.colour is None:
        return "NT"
    if test.scoring in ("fcw", "fcwttc26"):
        w = row["warning_ttc_s"]
        return f"{float(w):.1f}s" if w != "" else "no FCW"
    if str(row["contact"]) != "True":
        return "✓"
    key = "relative_impact_speed_kmh" if test.relative else "impact_speed_kmh"
    return f"{float(row[key]):.0f}"


def grid_figure(test: NcapTest, rows: list[dict], scores: list[PointScore]) -> Figure:
    """The scenario's grid (``rows`` and ``scores`` of its points, in the same order)."""
    lightings = [lt for lt in test.lightings if any(r["lighting"] == lt for r in rows)]
    ys = _order([str(r["row"]) for r in rows])
    xs = _order([str(r["col"]) for r in rows])
    width = max(4.8, 1.4 + 0.75 * len(xs) * len(lightings))  # room for the legend
    fig = Figure(figsize=(width, 1.6 + 0.32 * len(ys)))
    axes = fig.subplots(1, len(lightings), squeeze=False)[0]
    for ax, light in zip(axes, lightings, strict=True):
        for r, s in zip(rows, scores, strict=True):
            if r["lighting"] != light:
                continue
            x, y = xs.index(str(r["col"])), ys.index(str(r["row"]))
            rgb = NOT_TESTED_RGB if s.colour is None else RGB[s.colour]
            ax.add_patch(Rectangle((x, y), 1, 1, facecolor=rgb, edgecolor="white", lw=1.5))
            dark = s.colour in (Colour.GREEN, Colour.BROWN, Colour.RED)
            ax.text(x + 0.5, y + 0.5, _cell_text(test, r, s), ha="center", va="center",
                    fontsize=8, color="white" if dark else "black")  # fmt: skip
        ax.set_xlim(0, len(xs))
        ax.set_ylim(len(ys), 0)
        ax.set_xticks([i + 0.5 for i in range(len(xs))], xs if test.col else [""] * len(xs))
        ax.set_yticks([i + 0.5 for i in range(len(ys))], ys)
        ax.set_xlabel(" / ".join(c for c in (test.col, test.col2) if c))
        ax.set_ylabel(test.row)
        ax.tick_params(length=0, labelsize=8)
        ax.set_title(f"{test.key} {light}", fontsize=9)
    fig.legend(
        handles=[Patch(color=RGB[c], label=c.value) for c in Colour]
        + [Patch(color=NOT_TESTED_RGB, label="not tested")],
        loc="lower center", ncol=6, fontsize=7, frameon=False,
    )  # fmt: skip
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    return fig


def write_grid(path: Path, test: NcapTest, rows: list[dict], scores: list[PointScore]) -> Path:
    """Save the scenario's grid as a PNG (atomically)."""
    fig = grid_figure(test, rows, scores)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return path
