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
from matplotlib.patches import Patch

from hiyari.atomic import atomic_path
from hiyari.risk.cc.boundary import CutInDatasheet, CutOutDatasheet, DecelDatasheet
from hiyari.risk.cc.model import CCParams
from hiyari.units import KMH_PER_MPS

PREVENTABLE = "#7fc97f"
UNPREVENTABLE = "#f4a6a6"
EXCLUDED = "0.55"
DPI = 110


def _model_note(p: CCParams) -> str:
    judge = (
        f"danger = judgement + {p.perception_time_s:g} s"
        if p.judgement == "time"
        else f"danger at {p.wander_m + p.danger_lateral_m:g} m lateral"
    )
    aeb = (
        f"with AEB ({p.aeb_decel_g:g} g over {p.aeb_ramp_time_s:g} s at TTC < {p.aeb_ttc_s:g} s)"
        if p.aeb
        else "driver only (no AEB)"
    )
    return (
        f"C&C driver: wander {p.wander_m:g} m, {judge}, reaction {p.reaction_delay_s:g} s, "
        f"{p.max_decel_g:g} g reached in {p.ramp_time_s:g} s; {aeb}. Ego "
        f"{p.ego_length_m:g} x {p.ego_width_m:g} m, others {p.other_length_m:g} x "
        f"{p.other_width_m:g} m, lanes {p.lane_width_m:g} m."
    )


def _save(fig: Figure, path: Path) -> Path:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI)
    return path


def _panel_grid(n: int) -> tuple[int, int]:
    cols = 3 if n > 4 else max(n, 1)
    return -(-n // cols), cols


def plot_cut_in(
    sheet: CutInDatasheet, path: str | Path, dv_panels_kmh: tuple[float, ...] | None = None
) -> Path:
    """Cut-in datasheet: one panel per relative speed Ve0 - Vo0, boundary dx0 against Vy.

    In this model the outcome depends on Ve0 and Vo0 only through their difference, so each
    panel's curve holds for every Ve0 of the sheet (the drawn curve is the largest boundary
    over Ve0; the panel says if Ve0 changes it).
    """
    dv = sheet.dv_kmh
    if dv_panels_kmh is None:
        available = np.unique(dv[dv > 0])
        wanted = [v for v in (10, 20, 30, 40, 50) if v in available]
        dv_panels_kmh = tuple(wanted) if wanted else tuple(available[-5:])
    rows, cols = _panel_grid(len(dv_panels_kmh) + 1)
    fig = Figure(figsize=(4.6 * cols, 3.7 * rows + 0.9), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False, sharey=True)
    finite = sheet.boundary_dx0_m[np.isfinite(sheet.boundary_dx0_m)]
    y_top = max(10.0, 1.1 * float(finite.max()) if finite.size else 10.0)
    vy_all = np.unique(sheet.vy_mps)
    for ax, target in zip(axes.flat, dv_panels_kmh, strict=False):
        sel = np.isclose(dv, target)
        vys = np.unique(sheet.vy_mps[sel])
        b = sheet.boundary_dx0_m[sel]
        hi = np.array([b[sheet.vy_mps[sel] == v].max() for v in vys])
        lo = np.array([b[sheet.vy_mps[sel] == v].min() for v in vys])
        ve_range = sheet.ve0_kmh[sel]
        top = np.where(np.isfinite(hi), hi, y_top)
        ax.fill_between(vys, 0, top, color=UNPREVENTABLE, step=None, lw=0)
        ax.fill_between(vys, np.minimum(top, y_top), y_top, color=PREVENTABLE, lw=0)
        ax.plot(vys, np.where(np.isfinite(hi), hi, np.nan), color="k", lw=1.6)
        both = np.isfinite(hi) & np.isfinite(lo)
        spread = float(np.max(hi[both] - lo[both], initial=0.0))
        if spread > 1e-6:
            ax.fill_between(vys, lo, hi, color="0.3", alpha=0.35, lw=0)
        note = (
            f"Ve0 {ve_range.min():g}–{ve_range.max():g} km/h: same curve"
            if spread <= 1e-6
            else f"Ve0 {ve_range.min():g}–{ve_range.max():g} km/h: band = spread over Ve0"
        )
        if np.isinf(hi).any():
            note += f"\nno Preventable gap at Vy ≤ {vys[np.isinf(hi)].max():g} m/s"
            if np.isinf(hi).all():
                note = (
                    f"Ve0 {ve_range.min():g}–{ve_range.max():g} km/h\n"
                    "no Preventable gap at any Vy:\nthe C&C driver collides at every dx0"
                )
        ax.text(
            0.97,
            0.96,
            note,
            transform=ax.transAxes,
            ha="right",
            va="top",
            fontsize=8,
            bbox={"fc": "white", "ec": "0.7", "alpha": 0.85},
        )
        ax.set_title(f"Ve0 − Vo0 = {target:g} km/h")
        ax.set_xlim(0, float(vy_all.max()))
        ax.set_ylim(0, y_top)
        ax.grid(alpha=0.3)
    _cut_in_summary(sheet, axes.flat[len(dv_panels_kmh)], y_top)
    for ax in axes.flat[len(dv_panels_kmh) + 1 :]:
        ax.set_visible(False)
    for ax in axes.flat[: len(dv_panels_kmh)]:
        ax.set_xlabel("cut-in lateral velocity Vy (m/s)")
        ax.xaxis.set_tick_params(labelbottom=True)
    for ax in axes[:, 0]:
        ax.set_ylabel("initial gap dx0, ego front → other rear (m)")
    fig.legend(
        handles=[
            Patch(color=PREVENTABLE, label="Preventable: collision not permitted"),
            Patch(color=UNPREVENTABLE, label="Unpreventable"),
            Patch(color="k", label="Preventable boundary"),
        ],
        loc="outside lower center",
        ncol=3,
    )
    res = f", boundary rounded up to {sheet.resolution_m:g} m" if sheet.resolution_m else ""
    fig.suptitle(
        f"Cut-in Preventable boundary (cf. JAMA Fig. 26){res}\n{_model_note(sheet.params)}",
        fontsize=9.5,
    )
    return _save(fig, Path(path))


def _cut_in_summary(sheet: CutInDatasheet, ax: Axes, y_top: float) -> None:
    """Boundary against relative speed, one curve per Vy: where the Preventable gap ends."""
    dv = sheet.dv_kmh
    vys = np.unique(sheet.vy_mps)
    shown = [v for v in (0.5, 1.0, 2.0, 3.0) if np.isclose(vys, v).any()] or list(vys[-4:])
    colors = ["#1b9e77", "#d95f02", "#7570b3", "#e7298a"]
    none_from = []
    for vy, color in zip(shown, colors, strict=False):
        sel = np.isclose(sheet.vy_mps, vy)
        dvs = np.unique(dv[sel])
        b = np.array([sheet.boundary_dx0_m[sel & np.isclose(dv, d)].max() for d in dvs])
        ax.plot(
            dvs, np.where(np.isfinite(b), b, np.nan), color=color, lw=1.6, label=f"Vy = {vy:g} m/s"
        )
        if np.isinf(b).any():
            none_from.append(dvs[np.isinf(b)].min())
    if none_from:
        start = min(none_from)
        ax.axvspan(start, dv.max(), color=UNPREVENTABLE, lw=0)
        ax.text(
            start - 0.5,
            y_top * 0.75,
            f"no Preventable gap\nat ≥ {start:g} km/h →",
            fontsize=8,
            ha="right",
        )
    ax.set_xlim(0, dv.max())
    ax.set_ylim(0, y_top)
    ax.set_xlabel("relative speed Ve0 − Vo0 (km/h)")
    ax.set_title("boundary vs relative speed (Preventable above each curve)", fontsize=9.5)
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)


def plot_cut_out(
    sheet: CutOutDatasheet, path: str | Path, vy_panels_mps: tuple[float, ...] | None = None
) -> Path:
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
    return _save(fig, Path(path))


def plot_decel(sheet: DecelDatasheet, path: str | Path) -> Path:
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
    levels = [lv for lv in (1, 2, 5, 10, 20, 40) if np.nanmin(gap) < lv < np.nanmax(gap)]
    if levels:
        cs = ax.contour(ve, gx, gap, levels=levels, colors="0.25", linewidths=0.8)
        ax.clabel(cs, fmt="%g m", fontsize=8)
    boundary_drawn = bool(np.nanmin(gap) < 0 < np.nanmax(gap))
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
    if thw_levels:
        cs2 = ax2.contour(ve, gx, thw, levels=thw_levels, colors="0.25", linewidths=0.8)
        ax2.clabel(cs2, fmt="%g s", fontsize=8)
    filled = ax2.contourf(ve, gx, thw, levels=12, cmap="viridis")
    fig.colorbar(filled, ax=ax2, label="smallest Preventable THW (s)")
    if np.nanmin(thw) < p.thw_s < np.nanmax(thw):
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
    return _save(fig, Path(path))
