"""Judge an automated driving system against UN R157 (JAMA Annex G) test points.

Every point of a points file (``hiyari r157 points``) runs through the closed loop as a
concrete scenario, once per perception condition (perfect perception, or the sensor stack
under each chosen disturbance preset). A point in the Preventable region passes when the ego
does not collide (the C&C criterion); points in the unpreventable region are run and reported
but carry no pass / fail. The system passes a condition when every Preventable point passes.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hiyari.atomic import atomic_path
from hiyari.bridge.campaign.pool import PoolOptions, run_all
from hiyari.bridge.campaign.sweep import run_one
from hiyari.bridge.scenario.result import JUDGE_KEYS
from hiyari.bridge.scenario.toml_file import SENSOR_NAMES, ConcreteScenario
from hiyari.errors import HiyariError
from hiyari.risk.cc.r157_points import R157Point
from hiyari.units import G


@dataclass(frozen=True)
class JudgeOptions:
    """Conditions and execution. ``presets`` apply with ``perception="sensors"`` only."""

    perception: str = "perfect"
    presets: tuple[str, ...] = ("clear",)
    sensors: tuple[str, ...] = SENSOR_NAMES
    aeb_delay: float = 0.2
    step_length: float = 0.05
    settle_time: float = 8.0  # s simulated after the manoeuvre can have played out
    workers: int = 2
    backend: str = "local"
    sample: int | None = None  # run a seeded random subset of this many points
    seed: int = 1
    lane_width: float = 3.5


@dataclass
class JudgeReport:
    """Outcome per condition: counts and the failing points' ids."""

    conditions: list[str]
    rows: list[dict] = field(default_factory=list)

    def summary(self) -> dict[str, dict]:
        out = {}
        for cond in self.conditions:
            rows = [r for r in self.rows if r["condition"] == cond]
            prev = [r for r in rows if r["expected"] == "preventable"]
            failed = [r["id"] for r in prev if r["verdict"] != "pass"]
            out[cond] = {
                "points": len(rows),
                "preventable": len(prev),
                "passed": len(prev) - len(failed),
                "failed": len(failed),
                "unpreventable_collided": sum(
                    r["collision"] == "True" for r in rows if r["expected"] != "preventable"
                ),
                "verdict": "pass" if not failed else "fail",
                "failed_points": failed,
            }
        return out


def duration_for(point: R157Point, options: JudgeOptions) -> float:
    """Simulated seconds that cover the manoeuvre and its consequences."""
    w = options.lane_width
    if point.scenario == "cut-in":
        return w / point.vy_mps + options.settle_time
    if point.scenario == "cut-out":
        travel = (point.dx0_f_m + 2.0 * point.ve0_mps + 10.0) / max(point.ve0_mps, 1.0)
        return max(w / point.vy_mps, travel) + options.settle_time
    return point.ve0_mps / (G * point.gx_max_g) + options.settle_time


def point_scenario(
    point: R157Point, index: int, options: JudgeOptions, perception: str, preset: str
) -> ConcreteScenario:
    """The concrete closed-loop scenario of one test point."""
    if point.scenario == "cut-in":
        params = {
            "ve0_kmh": point.ve0_kmh,
            "vo0_kmh": point.vo0_kmh,
            "dx0_m": point.dx0_m,
            "vy_ms": point.vy_mps,
        }
    elif point.scenario == "cut-out":
        params = {"ve0_kmh": point.ve0_kmh, "vy_ms": point.vy_mps, "dx0_f_m": point.dx0_f_m}
    elif point.scenario == "decel":
        params = {"ve0_kmh": point.ve0_kmh, "gx_max_g": point.gx_max_g}
    else:
        raise HiyariError(f"point {point.id}: unknown scenario {point.scenario!r}")
    return ConcreteScenario(
        type=point.scenario,
        name=point.id,
        index=index,
        seed=options.seed,
        duration=duration_for(point, options),
        step_length=options.step_length,
        params=params,
        perception=perception,
        sensors=options.sensors,
        aeb_delay=options.aeb_delay,
        environment=preset,
    )


def judge(points: list[R157Point], options: JudgeOptions, progress: bool = True) -> JudgeReport:
    """Run every point under every condition; return the report (rows in point order)."""
    from tqdm import tqdm

    if options.sample is not None and options.sample < len(points):
        rng = np.random.default_rng(options.seed)
        keep = np.sort(rng.choice(len(points), size=options.sample, replace=False))
        points = [points[i] for i in keep]
    if options.perception == "sensors":
        conditions = [("sensors", p) for p in options.presets]
    else:
        conditions = [(options.perception, "clear")]
    runs, meta = [], []
    for perception, preset in conditions:
        for p in points:
            runs.append(point_scenario(p, len(runs), options, perception, preset))
            meta.append((p, f"{perception}/{preset}" if perception == "sensors" else perception))
    report = JudgeReport([c for c in dict.fromkeys(m[1] for m in meta)])
    results: dict[int, dict] = {}
    pool = PoolOptions(workers=options.workers, backend=options.backend)
    with tqdm(total=len(runs), unit="run", disable=not progress, desc="r157 judge") as bar:
        for _, (row, _) in run_all(run_one, runs, pool):
            results[row["index"]] = row
            bar.update(1)
    for i, (point, cond) in enumerate(meta):
        r = results[i]
        if r["status"] != "ok":
            verdict = "error"
        elif point.expected != "preventable":
            verdict = "n/a"
        else:
            verdict = "fail" if r["collision"] else "pass"
        report.rows.append(
            {
                "id": point.id,
                "scenario": point.scenario,
                "point": point.point,
                "condition": cond,
                "ve0_kmh": point.ve0_kmh,
                "vo0_kmh": point.vo0_kmh,
                "dx0_m": point.dx0_m,
                "vy_mps": point.vy_mps,
                "gx_max_g": point.gx_max_g,
                "dx0_f_m": point.dx0_f_m,
                "boundary_m": point.boundary_m,
                "offset_m": point.offset_m,
                "expected": point.expected,
                **{k: r[k] for k in JUDGE_KEYS},
                "collision": str(bool(r["collision"])) if r["status"] == "ok" else "",
                "verdict": verdict,
                "error": r["error"],
            }
        )
    return report


def write_report(report: JudgeReport, out_dir: Path) -> list[Path]:
    """judge.csv (every point x condition), summary.json and one PNG per scenario type."""
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
    for scenario in ("cut-in", "cut-out", "decel"):
        rows = [r for r in report.rows if r["scenario"] == scenario]
        if rows:
            paths.append(
                plot_judge(rows, scenario, report.conditions, out_dir / f"judge_{scenario}.png")
            )
    return paths


_STYLE = {
    "pass": ("tab:green", "o", "pass (Preventable)"),
    "fail": ("tab:red", "X", "FAIL (Preventable, collided)"),
    "n/a": ("0.55", "s", "unpreventable point"),
    "error": ("k", "*", "run error"),
}


def plot_judge(rows: list[dict], scenario: str, conditions: list[str], out: Path) -> Path:
    """Points over the datasheet axes, coloured by verdict; one column per condition."""
    from matplotlib.figure import Figure

    if scenario == "cut-in":
        xk, yk, xl, yl = "vy_mps", "dx0_m", "lateral velocity Vy (m/s)", "initial gap dx0 (m)"
        group = lambda r: f"Ve0-Vo0 = {r['ve0_kmh'] - r['vo0_kmh']:.0f} km/h"  # noqa: E731
    elif scenario == "cut-out":
        xk, yk, xl, yl = (
            "ve0_kmh",
            "dx0_f_m",
            "ego speed Ve0 (km/h)",
            "gap lead to stopped car dx0_f (m)",
        )
        group = lambda r: "all Vy"  # noqa: E731
    else:
        xk, yk, xl, yl = (
            "ve0_kmh",
            "gx_max_g",
            "ego speed Ve0 (km/h)",
            "lead deceleration Gx_max (g)",
        )
        group = lambda r: "THW 2 s"  # noqa: E731
    groups = sorted(
        {group(r) for r in rows}, key=lambda g: float(g.split("=")[1].split()[0]) if "=" in g else 0
    )
    nrow, ncol = len(groups), len(conditions)
    fig = Figure(figsize=(4.2 * ncol + 1, 2.6 * nrow + 1))
    axes = fig.subplots(nrow, ncol, squeeze=False, sharex=True)
    for i, g in enumerate(groups):
        for j, cond in enumerate(conditions):
            ax = axes[i][j]
            sel = [r for r in rows if group(r) == g and r["condition"] == cond]
            boundary = sorted((r[xk], r[yk]) for r in sel if r["point"] == "boundary")
            if boundary and scenario == "cut-in":
                ax.plot(*zip(*boundary, strict=True), "k-", lw=1, label="C&C boundary")
            for verdict, (color, marker, label) in _STYLE.items():
                pts = [(r[xk], r[yk]) for r in sel if r["verdict"] == verdict]
                if pts:
                    ax.scatter(*zip(*pts, strict=True), c=color, marker=marker, s=14, label=label)
            ax.set_title(f"{cond}: {g}", fontsize=8)
            ax.grid(alpha=0.3)
            if i == nrow - 1:
                ax.set_xlabel(xl)
            if j == 0:
                ax.set_ylabel(yl, fontsize=8)
    handles, labels = [], []
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="upper center", ncol=min(5, len(labels)), fontsize=8)
    fig.suptitle(f"UN R157 {scenario} test points through the closed loop", y=1.0)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=100, format="png", bbox_inches="tight")
    return out
