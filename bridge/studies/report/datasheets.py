"""Datasheet figures of the Preventable boundaries, in the manner of JAMA Fig. 26, 28 and 30.

Each figure is drawn on its own matplotlib ``Figure`` (Agg, no pyplot state) and written
atomically as PNG. Green = Preventable (the C&C driver avoids the collision: an automated
system must too), red = Unpreventable, grey hatching = excluded by Annex G.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from hiyari.atomic import atomic_path
from hiyari.risk.cc.boundary import (
    CutInDatasheet,
    CutOutDatasheet,
    DecelDatasheet,
    Grid,
    SearchOptions,
    cut_in_datasheet,
    cut_out_datasheet,
    decel_datasheet,
)
from hiyari.risk.cc.model import CCParams
from hiyari.units import KMH_PER_MPS

PREVENTABLE = "#7fc97f"
UNPREVENTABLE = "#f4a6a6"
EXCLUDED = "0.55"
DPI = 110


def _model_note(p: CCParams) -> str:
    """The model's parameters and conventions, two lines for a figure title."""
    aeb = (
        f"with AEB ({p.aeb_decel_g:g} g over {p.aeb_ramp_time_s:g} s at TTC < {p.aeb_ttc_s:g} s)"
        if p.aeb
        else "driver only (no AEB)"
    )
    return (
        f"C&C driver: wander {p.wander_m:g} m, reaction {p.reaction_delay_s:g} s, "
        f"{p.max_decel_g:g} g reached in {p.ramp_time_s:g} s; {aeb}. Ego "
        f"{p.ego_length_m:g} x {p.ego_width_m:g} m, others {p.other_length_m:g} x "
        f"{p.other_width_m:g} m, lanes {p.lane_width_m:g} m.\n{p.convention_note()}"
    )


def _save(fig: Figure, path: Path) -> Path:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI)
    return path


def _panel_grid(n: int) -> tuple[int, int]:
    cols = 3 if n > 4 else max(n, 1)
    return -(-n // cols), cols


def cut_in_figure(
    sheet: CutInDatasheet,
    ve_rows_kmh: tuple[float, ...] | None = None,
    dv_cols_kmh: tuple[float, ...] | None = None,
) -> Figure:
    """Cut-in datasheet: one panel per (Ve0, Ve0 - Vo0), every colliding interval of dx0 at
    each Vy in red (Unpreventable), the rest Preventable, the boundary (upper end) in black.

    With the Annex G heading the other car's yaw depends on Vo0, so each ego speed has its
    own panels (lane-aligned contact would make rows of equal relative speed identical).
    """
    ve_all, dv_all = np.unique(sheet.ve0_kmh), np.unique(sheet.dv_kmh)
    if ve_rows_kmh is None:
        wanted = [v for v in (30, 60, 90, 120) if v in ve_all]
        ve_rows_kmh = tuple(wanted) if wanted else tuple(ve_all[-4:])
    if dv_cols_kmh is None:
        wanted = [v for v in (0, 10, 20, 30, 40, 50, 60) if v in dv_all]
        dv_cols_kmh = tuple(wanted) if wanted else tuple(dv_all[-7:])
    nr, nc = len(ve_rows_kmh), len(dv_cols_kmh)
    fig = Figure(figsize=(2.75 * nc + 0.8, 2.35 * nr + 1.6), layout="constrained")
    axes = fig.subplots(nr, nc, squeeze=False, sharex=True)
    vy_all = np.unique(sheet.vy_mps)
    width = float(np.min(np.diff(vy_all), initial=0.1)) if vy_all.size > 1 else 0.1
    upper = sheet.regions.upper
    for j, dv in enumerate(dv_cols_kmh):
        col = np.isclose(sheet.dv_kmh, dv)
        # one scale per relative speed, showing every finite end of the regions in it
        ends = np.concatenate([upper[col], sheet.regions.lo[col].ravel()])
        finite = ends[np.isfinite(ends)]
        y_top = max(1.0, 1.15 * float(finite.max()) if finite.size else 1.0)
        for i, ve in enumerate(ve_rows_kmh):
            ax = axes[i][j]
            sel = np.flatnonzero(col & np.isclose(sheet.ve0_kmh, ve))
            if sel.size == 0:
                ax.set_visible(False)
                continue
            _cut_in_panel(ax, sheet, sel, y_top, width)
            ax.set_title(f"Ve0 {ve:g}, Ve0 − Vo0 {dv:g} km/h", fontsize=9)
            ax.set_xlim(0, float(vy_all.max()) + width / 2)
            ax.set_ylim(0, y_top)
            ax.tick_params(labelsize=8, labelbottom=True)
    for i in range(nr):
        shown = [ax for ax in axes[i] if ax.get_visible()]
        if shown:
            shown[0].set_ylabel("dx0, ego front → other rear (m)", fontsize=8)
    for j in range(nc):
        shown = [axes[i][j] for i in range(nr) if axes[i][j].get_visible()]
        if shown:
            shown[-1].set_xlabel("cut-in lateral velocity Vy (m/s)", fontsize=8)
    fig.legend(
        handles=[
            Patch(color=PREVENTABLE, label="Preventable: collision not permitted"),
            Patch(color=UNPREVENTABLE, label="Unpreventable: the C&C driver collides"),
            Line2D([], [], color="k", lw=1.4, label="Preventable boundary (upper end)"),
            Patch(color=EXCLUDED, label="Vy infeasible at Vo0"),
        ],
        loc="outside lower center",
        ncol=4,
    )
    pockets = int(np.sum(sheet.regions.lo[:, 0] > 0))
    res = f"; boundary rounded up to {sheet.resolution_m:g} m" if sheet.resolution_m else ""
    fig.suptitle(
        f"Cut-in Preventable regions (cf. JAMA Fig. 26): every colliding interval of dx0{res}. "
        f"{pockets:,} of {upper.size:,} (Ve0, Vo0, Vy) have Preventable gaps below their "
        f"colliding ones (the ego passes before the other car enters)\n"
        + _model_note(sheet.params),
        fontsize=9.5,
    )
    return fig


def _cut_in_panel(
    ax: Axes, sheet: CutInDatasheet, sel: np.ndarray, y_top: float, width: float
) -> None:
    """Green background, red colliding intervals per Vy, black upper ends, grey infeasible."""
    ax.set_facecolor(PREVENTABLE)
    vys = sheet.vy_mps[sel]
    for k, v in zip(sel, vys, strict=True):
        for lo, hi in sheet.regions.intervals(int(k)):
            ax.bar(v, min(hi, y_top) - lo, bottom=lo, width=width, color=UNPREVENTABLE, lw=0)
    order = np.argsort(vys)
    up = sheet.regions.upper[sel][order]
    ax.plot(vys[order], np.where(np.isfinite(up), up, np.nan), color="k", lw=1.4)
    vy_max = float(np.unique(sheet.vy_mps).max())
    if vys.max() < vy_max - 1e-9:
        ax.axvspan(vys.max() + width / 2, vy_max + width / 2, color=EXCLUDED, lw=0)
    if np.isinf(up).any():
        none = vys[order][np.isinf(up)]
        ax.text(
            0.97,
            0.95,
            f"no Preventable gap above the red\nat Vy {none.min():g}–{none.max():g} m/s",
            transform=ax.transAxes,
            ha="right",
            va="top",
            fontsize=7,
            bbox={"fc": "white", "ec": "0.7", "alpha": 0.85},
        )


def plot_cut_in(sheet: CutInDatasheet, path: str | Path) -> Path:
    """Write :func:`cut_in_figure` as PNG."""
    return _save(cut_in_figure(sheet), Path(path))


def plot_cut_out(sheet: CutOutDatasheet, path: str | Path) -> Path:
    """Write :func:`cut_out_figure` as PNG."""
    return _save(cut_out_figure(sheet), Path(path))


def cut_out_figure(
    sheet: CutOutDatasheet, vy_panels_mps: tuple[float, ...] | None = None
) -> Figure:
    """Cut-out datasheet: one panel per lateral velocity, boundary dx0_f against Ve0."""
    vys = np.unique(sheet.vy_mps)
    if vy_panels_mps is None:
        wanted = [v for v in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0) if np.isclose(vys, v).any()]
        vy_panels_mps = tuple(wanted) if wanted else tuple(vys[-6:])
    rows, cols = _panel_grid(len(vy_panels_mps))
    fig = Figure(figsize=(4.6 * cols, 3.7 * rows + 0.9), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False, sharex=True, sharey=True)
    shown = np.isclose(sheet.vy_mps[:, None], np.array(vy_panels_mps)[None, :]).any(axis=1)
    finite = sheet.boundary_dx0_f_m[shown & np.isfinite(sheet.boundary_dx0_f_m)]
    y_top = max(100.0, 1.1 * float(finite.max()) if finite.size else 100.0)
    ve_all = sheet.ve0_kmh
    for ax, target in zip(axes.flat, vy_panels_mps, strict=False):
        sel = np.isclose(sheet.vy_mps, target)
        order = np.argsort(sheet.ve0_kmh[sel])
        ve = sheet.ve0_kmh[sel][order]
        b = sheet.boundary_dx0_f_m[sel][order]
        clear = sheet.lead_clear_dx0_f_m[sel][order]
        top = np.where(np.isfinite(b), np.minimum(b, y_top), y_top)
        ax.fill_between(ve, 0, top, color=UNPREVENTABLE, lw=0)
        ax.fill_between(ve, top, y_top, color=PREVENTABLE, lw=0)
        ax.fill_between(
            ve, 0, np.minimum(clear, y_top), facecolor="none", edgecolor=EXCLUDED, hatch="///", lw=0
        )
        ax.plot(ve, np.where(np.isfinite(b), b, np.nan), color="k", lw=1.6)
        ax.plot(ve, np.minimum(clear, y_top), color=EXCLUDED, lw=1, ls="--")
        ax.set_title(f"Vy = {target:.1f} m/s")
        if ve_all.max() > ve_all.min():  # one ego speed: matplotlib picks the span
            ax.set_xlim(float(ve_all.min()), float(ve_all.max()))
        ax.set_ylim(0, y_top)
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(vy_panels_mps) :]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("ego speed Ve0 = lead speed Vo0 (km/h)")
    for ax in axes[:, 0]:
        ax.set_ylabel("gap dx0_f, lead front → stopped vehicle (m)")
    fig.legend(
        handles=[
            Patch(color=PREVENTABLE, label="Preventable: collision not permitted"),
            Patch(color=UNPREVENTABLE, label="Unpreventable"),
            Patch(color="k", label="Preventable boundary"),
            Patch(
                facecolor="none",
                edgecolor=EXCLUDED,
                hatch="///",
                label="excluded: the lead itself hits the stopped vehicle",
            ),
        ],
        loc="outside lower center",
        ncol=4,
    )
    p = sheet.params
    fig.suptitle(
        f"Cut-out Preventable boundary (cf. JAMA Fig. 28): ego follows at THW {p.thw_s:g} s "
        f"(dx0 = {p.thw_s:g} s x Ve0), stopped vehicle ahead of the lead\n{_model_note(p)}",
        fontsize=9.5,
    )
    return fig


def plot_decel(sheet: DecelDatasheet, path: str | Path) -> Path:
    """Write :func:`decel_figure` as PNG."""
    return _save(decel_figure(sheet), Path(path))


def decel_figure(sheet: DecelDatasheet) -> Figure:
    """Deceleration datasheet. Left: Preventable / Unpreventable over (Ve0, Gx_max) at the
    following THW, with contours of the C&C driver's minimum gap. Right: the smallest
    following time headway at which the scenario would be Preventable."""
    ve = np.unique(sheet.ve0_kmh)
    gx = np.unique(sheet.gx_max_g)
    iv = np.searchsorted(ve, sheet.ve0_kmh)
    ig = np.searchsorted(gx, sheet.gx_max_g)
    prevent = np.full((gx.size, ve.size), np.nan)
    gap = np.full((gx.size, ve.size), np.nan)
    thw = np.full((gx.size, ve.size), np.nan)
    prevent[ig, iv] = sheet.preventable
    gap[ig, iv] = sheet.min_gap_m
    thw[ig, iv] = sheet.boundary_dx0_m / (sheet.ve0_kmh / KMH_PER_MPS)
    p = sheet.params
    fig = Figure(figsize=(13.0, 5.8), layout="constrained")
    ax, ax2 = fig.subplots(1, 2)
    ax.pcolormesh(
        ve,
        gx,
        prevent,
        cmap=ListedColormap([UNPREVENTABLE, PREVENTABLE]),
        vmin=0,
        vmax=1,
        shading="nearest",
    )
    # contours need at least 2 x 2 grid points; a single row or column shows colours only
    contoured = ve.size > 1 and gx.size > 1
    levels = [lv for lv in (1, 2, 5, 10, 20, 40) if np.nanmin(gap) < lv < np.nanmax(gap)]
    if contoured and levels:
        cs = ax.contour(ve, gx, gap, levels=levels, colors="0.25", linewidths=0.8)
        ax.clabel(cs, fmt="%g m", fontsize=8)
    boundary_drawn = contoured and bool(np.nanmin(gap) < 0 < np.nanmax(gap))
    if boundary_drawn:
        ax.contour(ve, gx, gap, levels=[0.0], colors="k", linewidths=2.0)
    all_ok = bool(np.all(sheet.preventable))
    summary = (
        "Preventable everywhere: no boundary appears"
        if all_ok
        else f"Unpreventable cases from {sheet.ve0_kmh[~sheet.preventable].min():g} km/h"
    )
    ax.set_title(
        f"following at THW {p.thw_s:g} s: {summary}\ncontours: C&C minimum gap (m)", fontsize=10
    )
    handles = [
        Patch(color=PREVENTABLE, label="Preventable: collision not permitted"),
        Patch(color=UNPREVENTABLE, label="Unpreventable"),
    ]
    if boundary_drawn:
        handles.append(Patch(color="k", label="Preventable boundary"))
    ax.legend(handles=handles, loc="upper left", fontsize=8)
    thw_levels = [
        lv for lv in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0) if np.nanmin(thw) < lv < np.nanmax(thw)
    ]
    if contoured and thw_levels:
        cs2 = ax2.contour(ve, gx, thw, levels=thw_levels, colors="0.25", linewidths=0.8)
        ax2.clabel(cs2, fmt="%g s", fontsize=8)
    if contoured:
        filled = ax2.contourf(ve, gx, thw, levels=12, cmap="viridis")
    else:
        filled = ax2.pcolormesh(ve, gx, thw, cmap="viridis", shading="nearest")
    fig.colorbar(filled, ax=ax2, label="smallest Preventable THW (s)")
    if contoured and np.nanmin(thw) < p.thw_s < np.nanmax(thw):
        ax2.contour(ve, gx, thw, levels=[p.thw_s], colors="w", linewidths=2.0)
    ax2.set_title(f"smallest following THW that is Preventable (white: {p.thw_s:g} s)", fontsize=10)
    for a in (ax, ax2):
        a.axvline(60, color="k", ls=":", lw=1)
        a.set_xlabel("ego speed Ve0 = lead speed Vo0 (km/h)")
        a.set_ylabel("lead deceleration Gx_max (g), step")
    fig.suptitle(
        f"Deceleration Preventable map (cf. JAMA Fig. 30); dotted: 60 km/h\n{_model_note(p)}",
        fontsize=9.5,
    )
    return fig


_DEFAULT = CCParams()
_VE0_KMH = Grid(10, 130, 1)
_SEARCH = SearchOptions()


def write_datasheets(
    out_dir: str | Path,
    params: CCParams = _DEFAULT,
    ve0_kmh: Grid = _VE0_KMH,
    search: SearchOptions = _SEARCH,
) -> list[Path]:
    """Compute the cut-in, cut-out and deceleration datasheets over ``ve0_kmh`` (default
    10–130 km/h at 1 km/h; cut-in relative speeds 0–60 km/h at 1 km/h, Vy 0.1–3.0 m/s at
    0.1 m/s, boundaries at 0.1 m; deceleration Gx_max 0.01–1.0 g) and write
    ``cut_in_boundary.csv/.png``, ``cut_out_boundary.csv/.png`` and ``decel_map.csv/.png``
    into ``out_dir``. Returns the paths written."""
    out = Path(out_dir)
    cut_in = cut_in_datasheet(ve0_kmh=ve0_kmh, params=params, search=search)
    cut_out = cut_out_datasheet(ve0_kmh=ve0_kmh, params=params, search=search)
    decel = decel_datasheet(ve0_kmh=ve0_kmh, params=params, search=search)
    return [
        cut_in.write_csv(out / "cut_in_boundary.csv"),
        plot_cut_in(cut_in, out / "cut_in_boundary.png"),
        cut_out.write_csv(out / "cut_out_boundary.csv"),
        plot_cut_out(cut_out, out / "cut_out_boundary.png"),
        decel.write_csv(out / "decel_map.csv"),
        plot_decel(decel, out / "decel_map.png"),
    ]
