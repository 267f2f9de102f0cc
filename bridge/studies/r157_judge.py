"""Judge an automated driving system against UN R157 (JAMA Annex G) test points.

Every point of a points file (``hiyari r157 points``) runs through the closed loop as a
concrete scenario, once per perception condition (perfect perception, or the sensor stack
under each chosen disturbance preset). A point in the Preventable region passes when the ego
does not collide (the C&C criterion); points in the unpreventable region are run and reported
but carry no pass / fail. The system passes a condition when every Preventable point passes.

Each point's expectation is checked against the C&C model the judge is given
(``JudgeOptions.params``; the points file's own when it is JSON): for a cut-in, whether its
gap lies in an exact colliding region of its (Ve0, Vo0, Vy). A file whose verdicts disagree
(made with another model or convention) is refused rather than judged against the wrong
expectation. A run whose worker process dies (a native crash, an out-of-memory kill) gets the
verdict "crashed" (counted per condition, and a failed condition if the point is Preventable);
the other runs go on. The figures show the points over those regions, one panel per ego speed and
relative speed, so nothing drawn mixes two ego speeds.
"""

from __future__ import annotations

import csv
import json
import textwrap
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from hiyari.atomic import atomic_path
from hiyari.bridge.loop.result import JUDGE_KEYS, RESULT_KEYS
from hiyari.bridge.loop.run import RunOptions, run_concrete
from hiyari.bridge.loop.warm import ProcessCache
from hiyari.bridge.openscenario.presets.toml_file import SENSOR_NAMES, ConcreteScenario
from hiyari.bridge.studies.pool import Crashed, PoolOptions, run_all
from hiyari.errors import HiyariError
from hiyari.risk.cc.boundary import cut_out_boundary
from hiyari.risk.cc.evaluator import cut_out_lead_clear_gap
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.r157_points import R157Point, expected_verdicts
from hiyari.risk.cc.regions import cut_in_regions
from hiyari.units import KMH_PER_MPS, G


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
    in_process: bool = False  # runs one after the other in this process (a crash ends all)
    sample: int | None = None  # run a seeded random subset of this many points
    seed: int = 1
    lane_width: float = 3.5
    params: CCParams = field(default_factory=CCParams)  # the C&C model of the expectations
    warm: bool = True  # each worker builds the road, scene and rig once (same rows)
    end_when_decided: bool = True  # stop a run once its judged values cannot change


def check_expectations(points: list[R157Point], params: CCParams) -> None:
    """Refuse points whose expected verdict is not the C&C model's under ``params``."""
    wrong = [
        p.id
        for p, verdict in zip(points, expected_verdicts(points, params), strict=True)
        if p.expected != verdict
    ]
    if wrong:
        raise HiyariError(
            f"{len(wrong)} of {len(points)} test points expect a verdict the C&C model "
            f"({params.convention_note()}) does not give, e.g. {wrong[0]}: regenerate them "
            "with 'hiyari r157 points' and the same model options"
        )


@dataclass
class JudgeReport:
    """Outcome per condition: counts and the failing points' ids."""

    conditions: list[str]
    rows: list[dict] = field(default_factory=list)
    params: CCParams = field(default_factory=CCParams)
    # summed over the runs: simulated seconds, wall seconds of the closed loops and of the
    # whole runs (road, scene, SUMO start included), CPU seconds of the runs (cast threads too)
    sim_seconds: float = 0.0
    loop_seconds: float = 0.0
    run_seconds: float = 0.0
    cpu_seconds: float = 0.0

    def summary(self) -> dict[str, dict]:
        out = {}
        for cond in self.conditions:
            rows = [r for r in self.rows if r["condition"] == cond]
            prev = [r for r in rows if r["expected"] == "preventable"]
            failed = [r["id"] for r in prev if r["verdict"] != "pass"]
            out[cond] = {
                "crashed": sum(r["verdict"] == "crashed" for r in rows),
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


#: This process's roads, ray-cast scenes and rigs: each pool worker fills its own on its
#: first point and reuses them for the rest (the only state a worker keeps between runs).
WORKER_CACHE = ProcessCache()


@dataclass(frozen=True)
class PointRun:
    """One run of the judge: the point's scenario and how to run it (JudgeOptions)."""

    scenario: ConcreteScenario
    warm: bool
    end_when_decided: bool


def run_point(task: PointRun) -> dict:
    """Run one point in this process; never raises (a failure is a row with the error).
    Besides the result columns, the run's costs (:data:`TIMING_KEYS`, seconds)."""
    cs = task.scenario
    warm = WORKER_CACHE.for_this_process() if task.warm else None
    options = RunOptions(end_when_decided=task.end_when_decided)
    wall, cpu = time.perf_counter(), time.process_time()
    row: dict = {"index": cs.index, "sim_seconds": 0.0, "loop_seconds": 0.0}
    try:
        res = run_concrete(cs, options, warm=warm)
    except Exception as exc:  # one failing point must not stop the judge
        msg = " ".join(f"{type(exc).__name__}: {exc}".split())
        row.update(status="failed", error=msg, **dict.fromkeys(RESULT_KEYS, ""))
    else:
        row.update(status="ok", error="", sim_seconds=res.sim_seconds, **res.row())
        row["loop_seconds"] = res.wall_seconds
    row["run_seconds"] = time.perf_counter() - wall
    row["cpu_seconds"] = time.process_time() - cpu
    return row


#: The cost columns of :func:`run_point`'s rows, summed into the JudgeReport's fields.
TIMING_KEYS = ("sim_seconds", "loop_seconds", "run_seconds", "cpu_seconds")


def crashed_row(task: PointRun, crash: Crashed) -> dict:
    """The row of a point whose worker process died (the signal in ``error``)."""
    return {
        "index": task.scenario.index,
        **dict.fromkeys(TIMING_KEYS, 0.0),
        "status": "crashed",
        "error": str(crash),
        **dict.fromkeys(RESULT_KEYS, ""),
    }


def judge(points: list[R157Point], options: JudgeOptions, progress: bool = True) -> JudgeReport:
    """Run every point under every condition; return the report (rows in point order)."""
    from tqdm import tqdm

    if options.sample is not None and options.sample < len(points):
        rng = np.random.default_rng(options.seed)
        keep = np.sort(rng.choice(len(points), size=options.sample, replace=False))
        points = [points[i] for i in keep]
    check_expectations(points, options.params)
    if options.perception == "sensors":
        conditions = [("sensors", p) for p in options.presets]
    else:
        conditions = [(options.perception, "clear")]
    runs, meta = [], []
    for perception, preset in conditions:
        for p in points:
            runs.append(point_scenario(p, len(runs), options, perception, preset))
            meta.append((p, f"{perception}/{preset}" if perception == "sensors" else perception))
    report = JudgeReport([c for c in dict.fromkeys(m[1] for m in meta)], params=options.params)
    results: dict[int, dict] = {}
    pool = PoolOptions(
        workers=options.workers, backend=options.backend, in_process=options.in_process
    )
    tasks = [PointRun(cs, options.warm, options.end_when_decided) for cs in runs]
    try:
        with tqdm(total=len(runs), unit="run", disable=not progress, desc="r157 judge") as bar:
            for i, row in run_all(run_point, tasks, pool):
                if isinstance(row, Crashed):
                    row = crashed_row(tasks[i], row)
                results[row["index"]] = row
                for key in TIMING_KEYS:
                    setattr(report, key, getattr(report, key) + row[key])
                bar.update(1)
    finally:
        WORKER_CACHE.clear()  # runs made in this process (in_process) leave nothing behind
    for i, (point, cond) in enumerate(meta):
        r = results[i]
        if r["status"] == "crashed":
            verdict = "crashed"
        elif r["status"] != "ok":
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
    """judge.csv (every point x condition), summary.json and one PNG per scenario type and
    condition (``judge_<scenario>.png``, with ``_<condition>`` when there are several)."""
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
    outcome = (
        f"{'PASS' if passed == len(prev) else 'FAIL'}: {passed} of {len(prev)} Preventable "
        f"points passed; {len(rows) - len(prev)} Unpreventable points"
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
