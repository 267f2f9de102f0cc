"""One Euro NCAP test point: the run, what the protocol measures in it (impact speed, speed
before the test window, warning time) and its score.

Measures come from the run's ground truth (bridge.loop.result): the true TTC over all actors,
the ego's speed, the first contact; the warning is the first step the stack's AEB is at its
warning stage or above (a stack without stages gives no warning).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.result import RunResult
from hiyari.bridge.loop.xosc_runs import XoscRun
from hiyari.bridge.studies.ncap import scoring, scoring2026
from hiyari.bridge.studies.ncap.protocols import CA2026, NcapTest
from hiyari.bridge.studies.ncap.stack import stack_factory
from hiyari.units import mps_to_kmh

#: Columns of the study's results.csv, in order.
COLUMNS = (
    "point_id", "test", "lighting", "index", "seed", "row", "col", "test_speed_kmh",
    "reference_kmh", "status", "error", "contact", "collided_with", "impact_speed_kmh",
    "relative_impact_speed_kmh", "warning_ttc_s", "aeb_first_time_s", "min_ttc_s",
    "speed_before_window_kmh", "final_speed_kmh", "tested", "untested_cause",
    "false_activations", "near_misses", "sim_seconds", "wall_seconds",
)  # fmt: skip


@dataclass(frozen=True)
class NcapPoint:
    """One run of the grid: ``point_id`` e.g. 'CCRs-day-007', the test, its lighting, the
    concrete OpenSCENARIO run and the stack factory spec ('' for hiyari's)."""

    point_id: str
    test: NcapTest
    lighting: str
    run: XoscRun
    stack: str = ""

    @property
    def index(self) -> int:
        """Run index in the test's Variations file."""
        return self.run.index

    @property
    def seed(self) -> int:
        """The run's seed."""
        return self.run.seed

    def label(self) -> str:
        """Short description: id and grid values."""
        col = f", {self.test.col}={self.run.params.get(self.test.col, '')}" * bool(self.test.col)
        return f"{self.point_id} ({self.test.row}={self.run.params.get(self.test.row, '')}{col})"


def simulate(point: NcapPoint, record_dir: Path | None = None) -> RunResult:
    """Run ``point`` in this process (recorded into ``record_dir/run.mcap`` when given)."""
    setup = replace(point.run.setup, stack=stack_factory(point.stack))
    with replace(point.run, setup=setup).spec() as spec:
        return execute(spec, RunOptions(out_dir=record_dir, record=record_dir is not None))


def run_point(point: NcapPoint) -> dict:
    """Run one test point and measure it; never raises: a failure becomes a row with the
    error (pool worker function)."""
    t0 = time.perf_counter()
    row = _grid_row(point)
    try:
        row.update(measure(point, simulate(point)), status="ok", error="")
    except Exception as exc:  # one failing run must not stop the grid
        row.update(status="failed", error=" ".join(f"{type(exc).__name__}: {exc}".split()))
    row["wall_seconds"] = round(time.perf_counter() - t0, 3)
    return row


def _grid_row(point: NcapPoint) -> dict:
    t, p = point.test, point.run.params
    return {
        "point_id": point.point_id,
        "test": t.key,
        "lighting": point.lighting,
        "index": point.index,
        "seed": point.seed,
        "row": p.get(t.row, ""),
        "col": "/".join(str(p.get(c, "")) for c in (t.col, t.col2) if c),
    }


def _kmh(v: float) -> float:
    return round(float(mps_to_kmh(v)), 3)


def _num(x: float) -> float | str:
    return round(float(x), 3) if math.isfinite(x) else ""


def measure(point: NcapPoint, res: RunResult) -> dict:
    """The protocol's measures of a finished run (km/h, s; '' where a value does not exist)."""
    t, p, s = point.test, point.run.params, res.series
    v = np.abs(np.asarray(s.ego_speed, float))
    ttc = np.asarray(s.ttc_true, float)
    test_kmh = abs(float(p["Ego_speed_kph"])) if "Ego_speed_kph" in p else _kmh(v[0])
    target_kmh = abs(float(p[t.target_speed])) if t.target_speed and t.target_speed in p else 0.0
    opens = np.flatnonzero(ttc <= scoring.WINDOW_TTC_S.value)  # type: ignore[operator]
    k0 = int(opens[0]) if len(opens) else len(v)
    _, worst = scoring.speed_held([float(mps_to_kmh(x)) for x in v[:k0]], test_kmh)
    stages = np.asarray(s.aeb_stage, int)
    warned = np.flatnonzero(stages >= 1)
    return {
        "test_speed_kmh": test_kmh,
        "reference_kmh": round(test_kmh - target_kmh, 3),
        "contact": res.collision,
        "collided_with": res.collided_with,
        "impact_speed_kmh": _kmh(res.impact_speed) if res.collision else "",
        "relative_impact_speed_kmh": _kmh(res.relative_impact_speed) if res.collision else "",
        "warning_ttc_s": _num(ttc[warned[0]]) if len(warned) else "",
        "aeb_first_time_s": _num(res.aeb_first_time),
        "min_ttc_s": _num(res.min_ttc),
        "speed_before_window_kmh": round(worst, 3),
        "final_speed_kmh": _kmh(res.final_speed),
        "tested": res.tested().tested,
        "untested_cause": res.tested().reason,
        "false_activations": res.false_activations(),
        "near_misses": len(res.near_misses()),
        "sim_seconds": round(res.sim_seconds, 3),
    }


def _number(value: object) -> float | None:
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return None


def point_weight(test: NcapTest, row: dict) -> float:
    """The weight of a results row's point in its scenario (scoring.point_weight): its test
    speed and overlap when the grid has them."""
    if test.protocol == CA2026:  # CA-FC 5.3.1: every Standard Range grid cell the same
        return 1.0
    speed = _number(row.get("row")) if test.row == "Ego_speed_kph" else None
    overlap = _number(row.get("col")) if test.col == "Overlap" else None
    return scoring.point_weight(test.key, speed, overlap)


def score_row(test: NcapTest, row: dict) -> scoring.PointScore:
    """The scored point of a results row (file values: strings or numbers)."""
    light, weight = row["lighting"], point_weight(test, row)
    if row["status"] != "ok":
        return scoring.PointScore(
            test.scenario_key, light, None, f"run failed: {row['error']}", weight=weight
        )
    if str(row.get("tested", "")) == "False":  # hiyari.risk.metrics.tested: never a pass
        return scoring.PointScore(
            test.scenario_key,
            light,
            None,
            f"not tested: {row.get('untested_cause', '')}",
            weight=weight,
        )
    test_kmh = float(row["test_speed_kmh"])
    held, worst = scoring.speed_held([float(row["speed_before_window_kmh"])], test_kmh)
    if not held:
        window = scoring.WINDOW_TTC_S.value
        below, above = scoring.SPEED_TOLERANCE_KMH.value  # type: ignore[misc]
        why = "it braked before the test began" if worst < test_kmh else "it was too fast"
        return scoring.PointScore(
            test.scenario_key, light, None,
            f"the ego was at {worst:.1f} km/h before the test window (true TTC {window} s), "
            f"not at its test speed {test_kmh:g} km/h (+{above:g} / -{below:g} km/h): {why}",
            weight=weight,
        )  # fmt: skip
    contact = str(row["contact"]) == "True"
    impact = _number(row.get("impact_speed_kmh")) if contact else 0.0
    impact = 0.0 if impact is None else impact
    if test.relative and contact:  # CCRm, targets moving along the ego's path: Vrel_impact
        impact = float(row["relative_impact_speed_kmh"])
    voids = False
    warning = _number(row.get("warning_ttc_s"))
    if test.scoring == "fcw":
        colour, _ = scoring.fcw_colour(test_kmh, warning, contact, impact)
    elif test.scoring == "ccr":
        colour = scoring.ccr_colour(test.key, test_kmh, contact, impact)
        limit = float(scoring.CCRS_AVOIDANCE_UP_TO_KMH.value)  # type: ignore[arg-type]
        voids = test.key == "CCRs" and contact and test_kmh <= limit + 1e-9
    elif test.scoring == "headon":
        colour = scoring.headon_colour(test_kmh, contact, impact)
    elif test.scoring == "avoidance":
        colour = scoring.avoidance_colour(contact)
    elif test.scoring == "rel26":
        colour = scoring2026.rel_colour(test_kmh, contact, impact)
        limit = float(scoring.CCRS_AVOIDANCE_UP_TO_KMH.value)  # type: ignore[arg-type]
        voids = test.key == "CCRs" and contact and test_kmh <= limit + 1e-9
    elif test.scoring == "fcw26":
        colour = scoring2026.fcw_rel_colour(test_kmh, warning, contact, impact)
    elif test.scoring == "fcwttc26":
        colour = scoring2026.fcw_ttc_colour(warning)
    elif test.scoring == "headon26":
        colour = scoring2026.reduction_colour(test_kmh, contact, impact)
    else:
        colour = scoring.impact_colour(contact, impact, float(row["reference_kmh"]))
    return scoring.PointScore(test.scenario_key, light, colour, weight=weight, voids_scenario=voids)
