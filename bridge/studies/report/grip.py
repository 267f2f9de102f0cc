"""Grip-use report: Markdown table and a PNG of grip use along the curve, JAMA bands shaded."""

from __future__ import annotations

from pathlib import Path

from hiyari.atomic import atomic_path, write_text_atomic
from hiyari.bridge.studies.grip.study import GripResult, GripStudy
from hiyari.risk.dynamics.grip import BANDS

_BAND_COLOURS = ("#e8f5e9", "#fff8e1", "#ffe0b2", "#ffcdd2")


def grip_markdown(results: list[GripResult], study: GripStudy) -> str:
    """One line per run: max grip use, JAMA region, stations where each band edge is passed."""
    r = study.road
    d = study.disturbance
    lines = [
        "# Vehicle-motion disturbances: grip use (JAMA 4.3.3)",
        "",
        f"Expressway curve R = {r.curve_radius:g} m, superelevation {100 * r.superelevation:g} %, "
        f"arc {r.curve_start + r.transition_length:g}-"
        f"{r.curve_start + r.transition_length + r.curve_length:g} m; gust {d.gust_m_s:g} m/s at "
        f"{d.gust_station_m:g} m; rut {1000 * d.rut_depth_m:g} mm at {d.rut_from_m:g}-{d.rut_to_m:g} m.",
        "Bands: normal <= 30 %, emergency avoidance 30-75 %, limit (ABS) 75-100 %, beyond >= 100 %.",
        "",
        "| surface | mu | speed km/h | max grip use % | region | > 30 % at m | > 75 % at m | > 100 % at m | lane departure at m |",
        "|---|---:|---:|---:|---|---|---|---|---|",
    ]
    for g in results:
        spans = [
            f"{a:.0f}-{b:.0f}" if (a, b) != (None, None) else "-"
            for a, b in (x if x else (None, None) for x in g.exceedances())
        ]
        dep = f"{g.run.departed_at:.0f}" if g.run.departed_at is not None else "-"
        lines.append(
            f"| {g.surface} | {g.mu:g} | {g.speed_kmh:g} | {100 * g.max_grip_use:.0f} | "
            f"{g.band_name} | " + " | ".join(spans) + f" | {dep} |"
        )
    return "\n".join(lines) + "\n"


def grip_figure(results: list[GripResult], path: Path) -> Path:
    """PNG: grip use against station, one panel per surface, one line per speed."""
    from matplotlib.figure import Figure

    surfaces = list(dict.fromkeys(g.surface for g in results))
    fig = Figure(figsize=(10, 2.4 * len(surfaces) + 0.6))
    axes = fig.subplots(len(surfaces), 1, sharex=True, squeeze=False)[:, 0]
    edges = (0.0, *BANDS, 1.6)
    for ax, surface in zip(axes, surfaces, strict=True):
        for lo, hi, c in zip(edges[:-1], edges[1:], _BAND_COLOURS, strict=True):
            ax.axhspan(100 * lo, 100 * hi, color=c, zorder=0)
        for g in (g for g in results if g.surface == surface):
            ax.plot(g.run.s, 100 * g.run.grip_use.clip(0, 1.6), label=f"{g.speed_kmh:g} km/h")
            if g.run.departed_at is not None:
                ax.axvline(g.run.departed_at, color="firebrick", ls=":", lw=1)
        ax.set_ylim(0, 160)
        ax.set_ylabel(
            f"{surface} (mu {results[[r.surface for r in results].index(surface)].mu:g})\ngrip use %"
        )
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[-1].set_xlabel("station along the expressway, m (dotted red: lane departure)")
    fig.suptitle("hiyari: grip use through the expressway curve, JAMA bands 30 / 75 / 100 %")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    return path


def write_grip_report(
    results: list[GripResult], study: GripStudy, out_dir: Path
) -> dict[str, Path]:
    """grip.md and grip.png in ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    return {
        "md": write_text_atomic(out_dir / "grip.md", grip_markdown(results, study)),
        "png": grip_figure(results, out_dir / "grip.png"),
    }
