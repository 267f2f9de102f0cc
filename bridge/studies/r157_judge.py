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

import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.result import JUDGE_KEYS, NOT_TESTED, RESULT_KEYS
from hiyari.bridge.loop.toml_runs import preset_spec
from hiyari.bridge.loop.warm import ProcessCache
from hiyari.bridge.openscenario.presets.toml_file import SENSOR_NAMES, ConcreteScenario
from hiyari.bridge.studies.pool import Crashed, PoolOptions, run_all
from hiyari.errors import HiyariError
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.r157_points import R157Point, expected_verdicts
from hiyari.units import G


@dataclass(frozen=True)
class JudgeOptions:
    """Conditions and execution. ``perception``: "perfect", "sensors" or "none", or a comma
    list of them (each its own condition: "perfect,sensors" compares the sensors with ground
    truth, hiyari.bridge.studies.r157_compare). ``presets`` apply to "sensors" only."""

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
    stack: str = ""  # "module:callable" stack factory of the ego ('' hiyari's default stack)


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
            untested = [r["id"] for r in prev if r["verdict"] == NOT_TESTED]
            failed = [r["id"] for r in prev if r["verdict"] not in ("pass", NOT_TESTED)]
            tested = [r for r in rows if r["verdict"] not in (NOT_TESTED, "crashed", "error")]
            verdict = "fail" if failed else "not tested" if untested else "pass"
            out[cond] = {
                "crashed": sum(r["verdict"] == "crashed" for r in rows),
                "points": len(rows),
                "tested": len(tested),
                "not_tested": sum(r["verdict"] == NOT_TESTED for r in rows),
                "preventable": len(prev),
                "passed": sum(r["verdict"] == "pass" for r in prev),
                "failed": len(failed),
                "preventable_not_tested": len(untested),
                "unpreventable_collided": sum(
                    r["collision"] == "True" for r in tested if r["expected"] != "preventable"
                ),
                "collisions": sum(r["collision"] == "True" for r in tested),
                "near_misses": sum(_count(r["near_misses"]) for r in tested),
                "false_activations": sum(_count(r["false_activations"]) for r in rows),
                # fail: a Preventable point collided; not tested: none did, but some were not
                # tested (nothing to pass on); pass: every Preventable point tested and passed
                "verdict": verdict,
                "failed_points": failed,
                "not_tested_points": untested,
            }
        return out


def _count(x: object) -> int:
    """A count column of a row (empty for a failed run)."""
    return int(x) if x not in ("", None) else 0


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
        stack=options.stack,
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
        with tempfile.TemporaryDirectory(prefix="hiyari-road-") as tmp:
            res = execute(preset_spec(cs, Path(tmp), warm), options)
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


def point_verdict(point: R157Point, row: dict) -> str:
    """A run's verdict: crashed / error (the run failed), not tested (the ego braked hard,
    stopped or left its lane before the manoeuvre started: hiyari.risk.metrics.tested; never
    a pass, whatever the point's region), n/a (Unpreventable), else fail on a collision and
    pass without one."""
    if row["status"] == "crashed":
        return "crashed"
    if row["status"] != "ok":
        return "error"
    if not row["tested"]:
        return NOT_TESTED
    if point.expected != "preventable":
        return "n/a"
    return "fail" if row["collision"] else "pass"


PERCEPTIONS = ("perfect", "sensors", "none")


def judge_conditions(options: JudgeOptions) -> list[tuple[str, str]]:
    """(perception, preset) of every condition: "sensors" once per preset, the others once
    (HiyariError for an unknown perception or an empty list)."""
    names = [n.strip() for n in options.perception.split(",") if n.strip()]
    unknown = [n for n in names if n not in PERCEPTIONS]
    if unknown or not names:
        raise HiyariError(
            f"--perception: unknown {', '.join(unknown) or 'empty list'} "
            f"(a comma list of {', '.join(PERCEPTIONS)})"
        )
    out: list[tuple[str, str]] = []
    for name in dict.fromkeys(names):
        out += [("sensors", p) for p in options.presets] if name == "sensors" else [(name, "clear")]
    return out


def judge(points: list[R157Point], options: JudgeOptions, progress: bool = True) -> JudgeReport:
    """Run every point under every condition; return the report (rows in point order)."""
    from tqdm import tqdm

    if options.sample is not None and options.sample < len(points):
        rng = np.random.default_rng(options.seed)
        keep = np.sort(rng.choice(len(points), size=options.sample, replace=False))
        points = [points[i] for i in keep]
    check_expectations(points, options.params)
    conditions = judge_conditions(options)
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
        verdict = point_verdict(point, r)
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
