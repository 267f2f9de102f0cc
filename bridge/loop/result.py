"""The result of one closed-loop run: summary, typed time series, detection counts, and the one
list of result fields that result.json, ``hiyari run``'s results.csv, the sweep table and the
R157 judge all take their columns from.

Inside: SI (m, s, m/s). Files: speeds in km/h, times in s, distances in m, 3 decimals; None
(JSON) or an empty cell (CSV) where a value does not exist (no collision, infinite TTC).
"""

from __future__ import annotations

import json
from collections import defaultdict
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from hiyari.atomic import atomic_path
from hiyari.risk.metrics.clearance import Passing, PassingClearances
from hiyari.risk.metrics.false_braking import (
    FalseActivationRule,
    FalseBraking,
    false_activations,
    false_braking,
)
from hiyari.risk.metrics.tested import RunTested, RunTestedRule, run_tested
from hiyari.units import mps_to_kmh


@dataclass
class DetectionStats:
    """Counts for one object-list source over a run."""

    frames: int = 0
    objects: int = 0
    true_positives: int = 0
    false_positives: int = 0
    target_frames: int = 0  # frames in which the scenario's target was detected
    target_first_time: float = float("nan")  # s
    target_first_range: float = float("nan")  # m, ego centre to target centre
    position_error_sum: float = 0.0  # m, over true positives

    def as_dict(self) -> dict:
        """JSON-ready counts (times s, ranges and errors m)."""
        mean_err = self.position_error_sum / self.true_positives if self.true_positives else None
        return {
            "frames": self.frames,
            "objects": self.objects,
            "true_positives": self.true_positives,
            "false_positives": self.false_positives,
            "target_frames": self.target_frames,
            "target_first_time_s": _num(self.target_first_time),
            "target_first_range_m": _num(self.target_first_range),
            "mean_position_error_m": None if mean_err is None else round(mean_err, 3),
        }


@dataclass
class TimeSeries:
    """One value per closed-loop step (all lists equally long, except ``conflict_distance``,
    which only scenarios with a conflict point fill).

    t: simulation time, s. ego_speed: m/s. ego_accel_cmd: the stack's command, m/s^2.
    gap: bumper to bumper to the scenario's target along the ego's heading, m (inf: no target).
    ttc_true: ground-truth TTC over all actors, s (inf: none within the horizon).
    headway_true: ground-truth time headway behind the nearest actor in or entering the ego's
    path, s (inf: none; risk.metrics.ground_truth.path_headway).
    near_miss_true: ground-truth time until some actor comes within its near-miss limit of
    the ego's sides, s (inf: none; risk.metrics.clearance.near_miss_time).
    ttc_stack: the ego stack's own smallest TTC, s. aeb_stage: AEBStage as int (decided this
    step). aeb_decel: the AEB deceleration applied this step (after the actuation delay and
    while latched), m/s^2 >= 0.
    conflict_distance: ego front to the conflict point along the ego's heading, m.
    """

    t: list[float] = field(default_factory=list)
    ego_speed: list[float] = field(default_factory=list)
    ego_accel_cmd: list[float] = field(default_factory=list)
    gap: list[float] = field(default_factory=list)
    ttc_true: list[float] = field(default_factory=list)
    headway_true: list[float] = field(default_factory=list)
    near_miss_true: list[float] = field(default_factory=list)
    ttc_stack: list[float] = field(default_factory=list)
    aeb_stage: list[int] = field(default_factory=list)
    aeb_decel: list[float] = field(default_factory=list)
    conflict_distance: list[float] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.t)

    def columns(self) -> dict[str, np.ndarray]:
        """The filled series by name (field order), as float arrays (for CSV and plots)."""
        return {
            f.name: np.asarray(getattr(self, f.name), dtype=float)
            for f in fields(self)
            if getattr(self, f.name)
        }


@dataclass
class RunResult:
    """Outcome of one closed-loop run. Speeds m/s, distances m, times s."""

    label: str
    collision: bool = False
    collided_with: str = ""
    collision_time: float = float("nan")
    impact_speed: float = 0.0  # ego speed at first contact
    relative_impact_speed: float = 0.0  # closing speed at first contact
    min_ttc: float = float("inf")  # true TTC over all actors
    min_gap: float = float("inf")  # bumper-to-bumper to the target
    stop_distance: float = float("nan")  # ego front to the conflict point at the first stop
    aeb_first_time: float = float("nan")  # the first AEB stage (any, warning included)
    aeb_brake_time: float = float("nan")  # the first braking AEB stage (partial or full)
    aeb_max_stage: int = 0
    final_speed: float = 0.0
    stop_trigger: bool = False  # the scenario's stop trigger ended the run
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0
    detection: dict[str, DetectionStats] = field(
        default_factory=lambda: defaultdict(DetectionStats)
    )
    series: TimeSeries = field(default_factory=TimeSeries)
    #: whether the scenario has a disturbance (an Event acting on an actor other than the
    #: ego), and the time it started (nan: not reached): hiyari.risk.metrics.tested
    has_disturbance: bool = False
    disturbance_time: float = float("nan")
    lane_left_time: float = float("nan")  # the ego first changed lane on an edge (nan: never)
    #: the first time the scenario's target was in line of sight of the ego (no other actor's
    #: footprint between them: hiyari.risk.metrics.visibility), and its range then (centres)
    target_sight_time: float = float("nan")
    target_sight_range: float = float("nan")
    #: the closest pass of every actor the ego passed (hiyari.risk.metrics.clearance)
    clearances: PassingClearances = field(default_factory=PassingClearances)
    tested_rule: RunTestedRule = field(default_factory=RunTestedRule)
    activation_rule: FalseActivationRule = field(default_factory=FalseActivationRule)

    def tested(self) -> RunTested:
        """Whether the run reached its disturbance untouched (hiyari.risk.metrics.tested)."""
        s = self.series
        return run_tested(
            s.t, s.ego_speed, s.ego_accel_cmd, self.disturbance_time, self.has_disturbance,
            self.lane_left_time, self.tested_rule,
        )  # fmt: skip

    def target_tracked_time(self) -> float:
        """The first time the stack's fused tracks held the scenario's target, s (nan: never)."""
        stats = self.detection.get("fusion")
        return stats.target_first_time if stats is not None else float("nan")

    def target_tracked_range(self) -> float:
        """The target's range (centres, m) when first tracked (nan: never)."""
        stats = self.detection.get("fusion")
        return stats.target_first_range if stats is not None else float("nan")

    def false_activations(self) -> int:
        """AEB stages and over-comfort braking with no ground-truth conflict
        (hiyari.risk.metrics.false_braking.false_activations)."""
        s = self.series
        near = s.near_miss_true if len(s.near_miss_true) == len(s) else None
        return false_activations(
            s.t, s.ego_accel_cmd, s.aeb_stage, s.ttc_true, self.activation_rule, near
        )[0]

    def near_misses(self) -> list[Passing]:
        """The actors passed closer than the near-miss limit (the one hit left out)."""
        return self.clearances.near_misses(exclude=self.collided_with)

    def min_clearance(self, vru: bool) -> float:
        """The smallest clearance (m) to a VRU (``vru``) or to a vehicle passed (inf: none),
        the one hit left out."""
        gaps = [
            p.clearance
            for name, p in self.clearances.passes.items()
            if p.vru == vru and name != self.collided_with
        ]
        return min(gaps, default=float("inf"))

    def false_braking(self) -> dict[str, FalseBraking]:
        """AEB and ACC decelerations without a ground-truth hazard (risk.metrics.false_braking)."""
        s = self.series
        aeb = s.aeb_decel if len(s.aeb_decel) == len(s) else np.zeros(len(s))
        headway = s.headway_true if len(s.headway_true) == len(s) else None
        near = s.near_miss_true if len(s.near_miss_true) == len(s) else None
        return false_braking(
            s.t, s.ego_accel_cmd, s.ttc_true, aeb, headway=headway, near_miss_time=near
        )

    def verdict(self) -> str:
        """'not tested', 'collision', 'near miss' or 'no collision' (in that order)."""
        if not self.tested().tested:
            return NOT_TESTED
        if self.collision:
            return "collision"
        return NEAR_MISS if self.near_misses() else "no collision"

    def as_dict(self) -> dict:
        """JSON-ready summary (no time series): every RESULT_FIELDS value, then the closest
        passes and detection."""
        doc = {f.key: f.value(self) for f in RESULT_FIELDS}
        doc["passes"] = [
            {
                "actor": p.actor,
                "vru": p.vru,
                "min_clearance_m": round(p.clearance, 3),
                "ego_speed_kmh": _kmh(p.speed),
                "time_s": _num(p.time),
                "limit_m": round(p.limit, 3),
                "near_miss": p.near_miss and p.actor != self.collided_with,
            }
            for _, p in sorted(self.clearances.passes.items())
        ]
        doc["detection"] = {k: v.as_dict() for k, v in sorted(self.detection.items())}
        return doc

    def row(self) -> dict:
        """The result-table columns (RESULT_KEYS) of this run."""
        return {f.key: f.value(self) for f in RESULT_FIELDS if f.in_table}


#: The verdicts a run can have besides "collision" and "no collision".
NOT_TESTED, NEAR_MISS = "not tested", "near miss"


def _num(x: float) -> float | None:
    return None if not np.isfinite(x) else round(float(x), 3)


def _kmh(v: float) -> float:
    return round(float(mps_to_kmh(v)), 2)


def _false_braking(source: str, attr: str, digits: int | None) -> Callable[[RunResult], object]:
    def value(r: RunResult) -> object:
        x = getattr(r.false_braking()[source], attr)
        return x if digits is None else round(x, digits)

    return value


@dataclass(frozen=True)
class ResultField:
    """One summary value of a run: its key in result.json, whether it is a result-table column
    (results.csv of ``hiyari run`` and ``hiyari sweep``) and one of the R157 judge's, and how it
    is read from a RunResult (file units)."""

    key: str
    value: Callable[[RunResult], object]
    in_table: bool = True
    in_judge: bool = False


#: The run summary, in file order: the one list of result fields.
RESULT_FIELDS: tuple[ResultField, ...] = (
    ResultField("label", lambda r: r.label, in_table=False),
    ResultField("collision", lambda r: r.collision, in_judge=True),
    ResultField("collided_with", lambda r: r.collided_with),
    ResultField("collision_time_s", lambda r: _num(r.collision_time), in_table=False),
    ResultField("impact_speed_kmh", lambda r: _kmh(r.impact_speed), in_judge=True),
    ResultField("relative_impact_speed_kmh", lambda r: _kmh(r.relative_impact_speed)),
    ResultField("min_ttc_s", lambda r: _num(r.min_ttc), in_judge=True),
    ResultField("min_gap_m", lambda r: _num(r.min_gap), in_judge=True),
    ResultField("stop_distance_m", lambda r: _num(r.stop_distance)),
    ResultField("aeb_first_time_s", lambda r: _num(r.aeb_first_time)),
    ResultField("aeb_brake_time_s", lambda r: _num(r.aeb_brake_time), in_judge=True),
    ResultField("aeb_max_stage", lambda r: r.aeb_max_stage),
    ResultField("tested", lambda r: r.tested().tested, in_judge=True),
    ResultField("untested_cause", lambda r: r.tested().reason, in_judge=True),
    ResultField("disturbance_time_s", lambda r: _num(r.disturbance_time)),
    # when the target could first be seen and when the stack first tracked it: what explains a
    # sensor verdict that differs from perfect perception's (hiyari.bridge.studies.r157_compare)
    ResultField("target_in_sight_s", lambda r: _num(r.target_sight_time), in_judge=True),
    ResultField("target_in_sight_range_m", lambda r: _num(r.target_sight_range), in_judge=True),
    ResultField("target_tracked_s", lambda r: _num(r.target_tracked_time()), in_judge=True),
    ResultField("target_tracked_range_m", lambda r: _num(r.target_tracked_range()), in_judge=True),
    ResultField("false_activations", lambda r: r.false_activations(), in_judge=True),
    ResultField("near_misses", lambda r: len(r.near_misses()), in_judge=True),
    ResultField("min_vru_clearance_m", lambda r: _num(r.min_clearance(True))),
    ResultField("min_vehicle_clearance_m", lambda r: _num(r.min_clearance(False))),
    ResultField("final_speed_kmh", lambda r: _kmh(r.final_speed)),
    *(
        ResultField(f"false_{src}_{key}", _false_braking(src, attr, digits))
        for src in ("aeb", "acc")
        for key, attr, digits in (
            ("brakings", "events", None),
            ("braking_s", "duration", 2),
            ("peak_decel_mps2", "peak_decel", 2),
        )
    ),
    ResultField("stop_trigger", lambda r: r.stop_trigger, in_table=False),
    ResultField("sim_seconds", lambda r: round(r.sim_seconds, 3), in_table=False),
    ResultField("wall_seconds", lambda r: round(r.wall_seconds, 3), in_table=False),
)
#: Result-table columns (results.csv of ``hiyari run`` and ``hiyari sweep``).
RESULT_KEYS: tuple[str, ...] = tuple(f.key for f in RESULT_FIELDS if f.in_table)
#: The result columns of the R157 judge's table (judge.csv).
JUDGE_KEYS: tuple[str, ...] = tuple(f.key for f in RESULT_FIELDS if f.in_judge)


#: Draws a finished run's figure into a PNG file and returns its path.
PlotRun = Callable[[RunResult, Path], Path]


def write_result(
    result: RunResult, scenario: Mapping[str, object], out_dir: Path, plot: PlotRun | None = None
) -> None:
    """result.json (``scenario``: its scenario section, then the summary), timeseries.csv and,
    with ``plot``, timeseries.png in ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    doc = {"scenario": dict(scenario), "result": result.as_dict()}
    with atomic_path(out_dir / "result.json") as tmp:
        tmp.write_text(json.dumps(doc, indent=2))
    columns = result.series.columns()
    table = np.array(list(columns.values()), dtype=float).T
    with atomic_path(out_dir / "timeseries.csv") as tmp:
        np.savetxt(tmp, table, delimiter=",", header=",".join(columns), comments="", fmt="%.6g")
    if plot is not None:
        plot(result, out_dir / "timeseries.png")
