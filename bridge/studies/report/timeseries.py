"""The time series figure of one run: speed, acceleration command, gap and TTC over time, shaded
by what the controller did."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from hiyari.atomic import atomic_path
from hiyari.bridge.loop.result import RunResult, TimeSeries
from hiyari.units import G, mps_to_kmh


def plot_timeseries(result: RunResult, out: Path) -> Path:
    """Write :func:`timeseries_figure` as PNG."""
    fig = timeseries_figure(result)
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return out


#: acceleration command (m/s^2) below which the ACC counts as braking
ACC_BRAKING = -0.3


def _spans(t: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """Time spans (s) of the runs of ``mask``, each sample holding until the next one (so a
    single sample still shows as one step wide)."""
    if t.size == 0:
        return []
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.05
    ends = np.append(t[1:], t[-1] + step)
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return [
        (float(t[a]), float(ends[b - 1]))
        for a, b in zip(*[np.flatnonzero(edges == e) for e in (1, -1)], strict=True)
    ]


def _braking_phases(s: TimeSeries) -> list[tuple[str, str, np.ndarray]]:
    """What the controller did, per sample: (label, colour, mask). The AEB by the deceleration
    it applied (each level its own shade), the ACC where it braked on its own."""
    accel = np.asarray(s.ego_accel_cmd, dtype=float)
    aeb = np.asarray(s.aeb_decel, dtype=float) if s.aeb_decel else np.zeros(accel.shape)
    phases = []
    levels = np.unique(np.round(aeb[aeb > 0] / G, 2))
    colours = ["#ffc078", "#ff8787", "#e599f7"]
    for k, level in enumerate(levels):
        on = np.isclose(np.round(aeb / G, 2), level)
        phases.append((f"AEB braking {level:g} g", colours[min(k, len(colours) - 1)], on))
    acc = (aeb <= 0) & (accel < ACC_BRAKING)
    if acc.any():
        phases.append((f"ACC braking (< {ACC_BRAKING:g} m/s²)", "#a5d8ff", acc))
    return phases


def timeseries_figure(result: RunResult) -> Figure:
    """Speed, acceleration command, gap and TTC over time, shaded by what the controller did
    (AEB braking by level, ACC braking), with the AEB stage decisions marked."""
    s = result.series
    t = np.asarray(s.t)
    fig = Figure(figsize=(8.5, 8.5), layout="constrained")
    axes = fig.subplots(4, 1, sharex=True)
    axes[0].plot(t, mps_to_kmh(np.asarray(s.ego_speed)), label="ego speed")
    axes[0].set_ylabel("speed (km/h)")
    axes[1].plot(t, np.asarray(s.ego_accel_cmd), color="k", lw=1.2, label="command")
    if s.aeb_decel:
        axes[1].plot(t, -np.asarray(s.aeb_decel), "--", color="tab:red", label="AEB applied")
    axes[1].set_ylabel("acceleration (m/s²)")
    gap = np.asarray(s.gap, dtype=float)
    gap_label = "gap to target"
    if s.conflict_distance:
        gap, gap_label = np.asarray(s.conflict_distance), "distance to conflict point"
    axes[2].plot(t, np.where(np.isfinite(gap), gap, np.nan), color="tab:orange", label=gap_label)
    axes[2].axhline(0, color="k", lw=0.6)
    axes[2].set_ylabel("distance (m)")
    for values, lab, style in (
        (s.ttc_true, "TTC (ground truth)", "-"),
        (s.ttc_stack, "TTC (ego stack)", "--"),
    ):
        v = np.asarray(values, dtype=float)
        axes[3].plot(t, np.where(v < 10, v, np.nan), style, label=lab)
    axes[3].set_ylim(0, 10)
    axes[3].set_ylabel("TTC (s)")
    axes[3].set_xlabel("simulation time (s)")
    phases = _braking_phases(s)
    stage = np.asarray(s.aeb_stage)
    decided = [(lvl, t[np.flatnonzero(stage >= lvl)[0]]) for lvl in (2, 3) if (stage >= lvl).any()]
    for ax in axes:
        for _, colour, mask in phases:
            for a, b in _spans(t, mask):
                ax.axvspan(a, b, color=colour, alpha=0.6, lw=0)
        for _, when in decided:
            ax.axvline(when, color="tab:red", lw=0.8, ls=":")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    handles = [Patch(color=c, alpha=0.6, label=lab) for lab, c, _ in phases]
    names = {2: "partial", 3: "full"}
    handles += [
        Line2D(
            [],
            [],
            color="tab:red",
            lw=0.8,
            ls=":",
            label=f"AEB decides {names[lvl]} at {when:.2f} s",
        )
        for lvl, when in decided
    ]
    if handles:
        fig.legend(
            handles=handles, loc="outside lower center", ncol=min(len(handles), 3), fontsize=8
        )
    verdict = (
        f"COLLISION with {result.collided_with} at {mps_to_kmh(result.impact_speed):.1f} km/h"
        if result.collision
        else "no collision"
    )
    shaded = "; shaded: what the controller did" if phases else "; no braking"
    fig.suptitle(f"{result.label}\n{verdict}{shaded}", fontsize=9)
    return fig
