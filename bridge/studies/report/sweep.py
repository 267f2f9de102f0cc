"""A sweep's summary figure: collision or not over the varied parameters."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from hiyari.atomic import atomic_path


def plot_sweep(name: str, varied: list[str], rows: list[dict], out: Path) -> Path | None:
    """PNG: each run's outcome (collision or not) over the first two ``varied`` parameters
    (or the first and the min TTC); ``rows`` as read from the sweep's results table."""
    ok = [r for r in rows if r["status"] == "ok"]
    if not ok or not varied:
        return None
    xk = varied[0]
    yk = varied[1] if len(varied) > 1 else "min_ttc_s"
    fig = Figure(figsize=(7, 5))
    ax = fig.subplots()
    for coll, color, label in (
        ("True", "tab:red", "collision"),
        ("False", "tab:green", "no collision"),
    ):
        pts = [(float(r[xk]), float(r[yk])) for r in ok if r["collision"] == coll and r[yk] != ""]
        if pts:
            ax.scatter(*zip(*pts, strict=True), c=color, label=label, s=25, edgecolors="k", lw=0.3)
    failed = [r for r in rows if r["status"] == "failed"]
    crashed = [r for r in rows if r["status"] == "crashed"]
    ax.set_xlabel(xk)
    ax.set_ylabel(yk)
    ax.grid(alpha=0.3)
    if ax.collections:  # no run had both values: nothing to label
        ax.legend()
    ax.set_title(
        f"{name}: {len(ok)} runs, {sum(r['collision'] == 'True' for r in ok)} "
        f"collisions, {len(failed)} failed" + f", {len(crashed)} crashed" * bool(crashed)
    )
    fig.tight_layout()
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return out
