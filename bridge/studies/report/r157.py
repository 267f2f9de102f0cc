"""The R157 judge's outputs: judge.csv, summary.json, one figure per scenario type and
condition, the points drawn over the C&C model's exact colliding regions, and with perfect
perception among other conditions differences.csv (hiyari.bridge.studies.r157_compare)."""

from __future__ import annotations

import csv
import json
import textwrap
from dataclasses import fields
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from hiyari.atomic import atomic_path
from hiyari.bridge.studies.r157_compare import PERFECT, Difference, differences, rig_reach_m
from hiyari.bridge.studies.r157_judge import JudgeReport
from hiyari.risk.cc.boundary import cut_out_boundary
from hiyari.risk.cc.evaluator import cut_out_lead_clear_gap
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.regions import cut_in_regions
from hiyari.units import KMH_PER_MPS


def write_report(report: JudgeReport, out_dir: Path) -> list[Path]:
    """judge.csv (every point x condition), summary.json, one PNG per scenario type and
    condition (``judge_<scenario>.png``, with ``_<condition>`` when there are several) and,
    when perfect perception is one of several conditions, differences.csv: every point whose
    verdict differs from perfect perception's, with the perception limit that explains it."""
    out_dir.mkdir(parents=True, exist_ok=True)
    csv_path = out_dir / "judge.csv"
    with atomic_path(csv_path) as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(report.rows[0]))
        w.writeheader()
        for r in report.rows:
            w.writerow({k: "" if v is None else v for k, v in r.items()})
    summary = out_dir / "summary.json"
    with atomic_path(summary) as tmp:
        tmp.write_text(json.dumps(report.summary(), indent=2))
    paths = [csv_path, summary]
    if PERFECT in report.conditions and len(report.conditions) > 1:
        paths.append(out_dir / "differences.csv")
        diffs = differences(report.rows, rig_reach_m())
        with atomic_path(paths[-1]) as tmp, tmp.open("w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=[fd.name for fd in fields(Difference)])
            w.writeheader()
            w.writerows(d.row() for d in diffs)
    for scenario in ("cut-in", "cut-out", "decel"):
        for cond in report.conditions:
            rows = [r for r in report.rows if r["scenario"] == scenario and r["condition"] == cond]
            if not rows:
                continue
            suffix = "" if len(report.conditions) == 1 else "_" + cond.replace("/", "-")
            out = out_dir / f"judge_{scenario}{suffix}.png"
            fig = judge_figure(rows, scenario, cond, report.params)
            with atomic_path(out) as tmp:
                fig.savefig(tmp, dpi=_DPI, format="png")
            paths.append(out)
    return paths


_DPI = 100
_STYLE = {
    "pass": ("tab:green", "o", "pass (Preventable)"),
    "fail": ("tab:red", "X", "FAIL (Preventable, collided)"),
    "n/a collided": ("0.2", "s", "Unpreventable point, collided (allowed)"),
    "n/a avoided": ("0.65", "s", "Unpreventable point, avoided"),
    "not tested": ("tab:orange", "v", "not tested (braked, stopped or left the lane before)"),
    "error": ("k", "*", "run error"),
    "crashed": ("tab:purple", "*", "run crashed (worker process died)"),
}
_REGION = "#f4a6a6"


def _kind(row: dict) -> str:
    """The row's key in :data:`_STYLE`: its verdict, Unpreventable points by outcome."""
    if row["verdict"] != "n/a":
        return row["verdict"]
    return "n/a collided" if row["collision"] == "True" else "n/a avoided"


def _scatter_verdicts(ax: Axes, rows: list[dict], xk: str, yk: str) -> None:
    for kind, (color, marker, label) in _STYLE.items():
        pts = [(r[xk], r[yk]) for r in rows if _kind(r) == kind]
        if pts:
            x, y = zip(*pts, strict=True)
            ax.scatter(
                x,
                y,
                c=color,
                marker=marker,
                s=22,
                label=label,
                zorder=3,
                lw=0.4,
                edgecolors="k" if kind == "fail" else "none",
            )


def _finish(fig: Figure, rows: list[dict], extra: list, title: str, params: CCParams) -> Figure:
    """Legend below the panels; title, outcome and conventions above them."""
    present = {_kind(r) for r in rows}
    handles = list(extra) + [
        Line2D([], [], color=color, marker=marker, ls="", markersize=8, label=label)
        for kind, (color, marker, label) in _STYLE.items()
        if kind in present
    ]
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4))
    prev = [r for r in rows if r["expected"] == "preventable"]
    passed = sum(r["verdict"] == "pass" for r in prev)
    untested = sum(r["verdict"] == "not tested" for r in rows)
    outcome = (
        f"{'PASS' if passed == len(prev) else 'FAIL'}: {passed} of {len(prev)} Preventable "
        f"points passed; {len(rows) - len(prev)} Unpreventable points; {untested} not tested"
    )
    note = textwrap.fill(params.convention_note(), width=int(13 * fig.get_figwidth()))
    fig.suptitle(f"{title}\n{outcome}\n{note}", fontsize=10)
    return fig


def _cut_in_figure(rows: list[dict], cond: str, params: CCParams) -> Figure:
    """One panel per (Ve0, Ve0 - Vo0): colliding regions of the C&C driver over (Vy, dx0),
    its Preventable boundary and the points coloured by verdict."""
    ves = sorted({r["ve0_kmh"] for r in rows})
    dvs = sorted({round(r["ve0_kmh"] - r["vo0_kmh"], 6) for r in rows})
    fig = Figure(figsize=(3.3 * len(ves) + 0.6, 2.5 * len(dvs) + 1.4), layout="constrained")
    axes = fig.subplots(len(dvs), len(ves), squeeze=False, sharex=True)
    vy_max = max(r["vy_mps"] for r in rows)
    for i, dv in enumerate(dvs):
        in_row = [r for r in rows if round(r["ve0_kmh"] - r["vo0_kmh"], 6) == dv]
        y_top = max(r["dx0_m"] for r in in_row) * 1.08 + 1.0  # one scale per relative speed
        for j, ve in enumerate(ves):
            ax = axes[i][j]
            sel = [r for r in in_row if r["ve0_kmh"] == ve]
            if not sel:
                ax.set_visible(False)
                continue
            _cut_in_regions_on(ax, ve, ve - dv, sorted({r["vy_mps"] for r in sel}), y_top, params)
            _scatter_verdicts(ax, sel, "vy_mps", "dx0_m")
            ax.set_title(f"Ve0 {ve:g} km/h, Ve0 − Vo0 {dv:g} km/h", fontsize=9)
            ax.set_xlim(0, vy_max + 0.1)
            ax.set_ylim(-0.04 * y_top, y_top)  # points at dx0 = 0 stay visible
            ax.grid(alpha=0.3)
            ax.tick_params(labelsize=8, labelbottom=True)
            if j == 0 or not axes[i][j - 1].get_visible():
                ax.set_ylabel("dx0 (m)", fontsize=9)
    for j in range(len(ves)):
        shown = [axes[i][j] for i in range(len(dvs)) if axes[i][j].get_visible()]
        if shown:
            shown[-1].set_xlabel("lateral velocity Vy (m/s)", fontsize=9)
    extra = [
        Patch(color=_REGION, label="C&C collides (Unpreventable region)"),
        Line2D([], [], color="k", lw=1.4, label="Preventable boundary (this Ve0, Vo0)"),
    ]
    return _finish(
        fig, rows, extra, f"UN R157 cut-in test points through the closed loop: {cond}", params
    )


def _cut_in_regions_on(
    ax: Axes, ve_kmh: float, vo_kmh: float, vys: list[float], y_top: float, params: CCParams
) -> None:
    """Shade the exact colliding dx0 intervals at each Vy and draw their upper end."""
    vy = np.array(vys)
    ones = np.ones(vy.size)
    regions = cut_in_regions(ve_kmh / KMH_PER_MPS * ones, vo_kmh / KMH_PER_MPS * ones, vy, params)
    width = float(np.min(np.diff(vy), initial=0.1)) if vy.size > 1 else 0.1
    for k in range(vy.size):
        for lo, hi in regions.intervals(k):
            ax.bar(vy[k], min(hi, y_top) - lo, bottom=lo, width=width, color=_REGION, lw=0)
    upper = regions.upper
    ax.plot(vy, np.where(np.isfinite(upper), upper, np.nan), "k-", lw=1.4)


def _cut_out_figure(rows: list[dict], cond: str, params: CCParams) -> Figure:
    """One panel per Ve0: the C&C Preventable boundary over (Vy, dx0_f), the gaps Annex G
    excludes, and the points."""
    ves = sorted({r["ve0_kmh"] for r in rows})
    cols = min(len(ves), 3)
    nrows = -(-len(ves) // cols)
    fig = Figure(figsize=(4.2 * cols + 0.6, 3.2 * nrows + 1.4), layout="constrained")
    axes = fig.subplots(nrows, cols, squeeze=False)
    y_top = max(r["dx0_f_m"] for r in rows) * 1.05 + 1.0
    vy = np.round(np.arange(0.1, max(r["vy_mps"] for r in rows) + 1e-9, 0.05), 9)
    for ax, ve in zip(axes.flat, ves, strict=False):
        sel = [r for r in rows if r["ve0_kmh"] == ve]
        v = np.full(vy.size, ve / KMH_PER_MPS)
        ok = vy <= v * np.tan(np.radians(params.max_heading_deg))
        b = cut_out_boundary(v[ok], vy[ok], params)
        clear = cut_out_lead_clear_gap(v[ok], vy[ok], params)
        ax.fill_between(vy[ok], 0, np.minimum(b, y_top), color=_REGION, lw=0)
        ax.fill_between(
            vy[ok],
            0,
            np.minimum(clear, y_top),
            facecolor="none",
            edgecolor="0.5",
            hatch="///",
            lw=0,
        )
        ax.plot(vy[ok], b, "k-", lw=1.4)
        _scatter_verdicts(ax, sel, "vy_mps", "dx0_f_m")
        ax.set_title(f"Ve0 = Vo0 = {ve:g} km/h", fontsize=9)
        ax.set_xlim(0, vy.max() + 0.1)
        ax.set_ylim(-0.04 * y_top, y_top)
        ax.grid(alpha=0.3)
        ax.set_xlabel("lateral velocity Vy (m/s)", fontsize=9)
        ax.set_ylabel("dx0_f, lead front → stopped car (m)", fontsize=9)
    for ax in axes.flat[len(ves) :]:
        ax.set_visible(False)
    extra = [
        Patch(color=_REGION, label="C&C collides (Unpreventable)"),
        Line2D([], [], color="k", lw=1.4, label="Preventable boundary"),
        Patch(facecolor="none", edgecolor="0.5", hatch="///", label="excluded: lead hits it"),
    ]
    return _finish(
        fig, rows, extra, f"UN R157 cut-out test points through the closed loop: {cond}", params
    )


def _decel_figure(rows: list[dict], cond: str, params: CCParams) -> Figure:
    """Ego speed x lead deceleration at the THW following gap, points by verdict."""
    fig = Figure(figsize=(7.5, 5.4), layout="constrained")
    ax = fig.subplots()
    _scatter_verdicts(ax, rows, "ve0_kmh", "gx_max_g")
    ax.set_xlabel("ego speed Ve0 = lead speed (km/h)")
    ax.set_ylabel("lead deceleration Gx_max (g), step")
    ax.set_title(f"following at THW {params.thw_s:g} s", fontsize=9)
    ax.grid(alpha=0.3)
    return _finish(fig, rows, [], f"UN R157 deceleration test points: {cond}", params)


def judge_figure(rows: list[dict], scenario: str, cond: str, params: CCParams) -> Figure:
    """The figure of one scenario type under one condition (rows of :class:`JudgeReport`)."""
    build = {"cut-in": _cut_in_figure, "cut-out": _cut_out_figure, "decel": _decel_figure}
    return build[scenario](rows, cond, params)
