"""Sensitivity of the SCT study's incident reduction to SCT_safe, penetration and pedestrian
demand: short studies around the main configuration, one parameter varied at a time, all with
the same seeds, so the seed's -68 % can be placed within the model's range.

Every point runs ``hours`` simulated hours per arm (unsignalised variant); points that only
change the SCT driver (SCT_safe, penetration) share the baseline arm of their demand.
bridge.studies.report.sct_sensitivity writes ``sensitivity.csv`` and ``sensitivity.png``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from hiyari.bridge.studies.sct.study import ArmTask, StudyConfig, build_inputs, run_tasks
from hiyari.bridge.studies.sct.summary import reduction, summarise
from hiyari.errors import HiyariError


@dataclass(frozen=True)
class SensitivityGrid:
    """Values tried per parameter (the main configuration's value is added to each)."""

    sct_safe: tuple[float, ...] = (2.0, 3.0, 6.0)
    penetration: tuple[float, ...] = (0.25, 0.5)
    persons_per_hour: tuple[float, ...] = (150.0, 600.0)


@dataclass(frozen=True)
class SensitivityPoint:
    """One point: the varied parameter and value, both arms' incidents and the travel-time
    cost (s per vehicle, SCT arm minus baseline)."""

    parameter: str
    value: float
    baseline_incidents: int
    sct_incidents: int
    reduction: float
    travel_time_cost: float


#: the varied parameters and their axis labels (the report draws one panel per parameter)
PARAMETERS = {
    "sct_safe": "SCT_safe, s",
    "penetration": "share of SCT vehicles",
    "persons_per_hour": "pedestrians per hour",
}


def _with(config: StudyConfig, parameter: str, value: float) -> StudyConfig:
    if parameter == "sct_safe":
        return replace(config, controller=replace(config.controller, sct_safe=value))
    return replace(config, **{parameter: value})


def run_sensitivity(
    config: StudyConfig,
    folder: str | Path,
    hours: float,
    grid: SensitivityGrid = SensitivityGrid(),
    jobs: int | None = None,
) -> list[SensitivityPoint]:
    """Run every point of ``grid`` around ``config`` for ``hours`` simulated hours per arm
    (inputs under ``folder``/sensitivity); the points in grid order, main value included."""
    if hours <= 0:
        raise HiyariError(f"sensitivity: hours must be > 0, got {hours}")
    short = replace(config, days=hours / 24.0, runs=1, variants=("unsignalised",))
    short.validate()
    root = Path(folder) / "sensitivity"
    points = [
        (p, float(v)) for p in PARAMETERS for v in sorted({*getattr(grid, p), _main(short, p)})
    ]
    # one demand per pedestrian volume; its baseline serves every point of that demand
    demands: dict[float, list[ArmTask]] = {}
    for p, v in points:
        pph = v if p == "persons_per_hour" else short.persons_per_hour
        if pph not in demands:
            demands[pph] = build_inputs(replace(short, persons_per_hour=pph), root / f"pph{pph:g}")
    tasks: list[ArmTask] = [t for ts in demands.values() for t in ts if t.arm == "baseline"]
    # the main configuration appears once per parameter: run each distinct SCT arm once
    arm_of: dict[tuple[float, float, float], int] = {}
    for p, v in points:
        study = _with(short, p, v)
        key = (study.persons_per_hour, study.controller.sct_safe, study.penetration)
        if key not in arm_of:
            sct = next(t for t in demands[key[0]] if t.arm == "sct")
            arm_of[key] = len(tasks)
            tasks.append(replace(sct, study=study))
    results = run_tasks(tasks, jobs)
    base = {
        t.study.persons_per_hour: r
        for t, r in zip(tasks, results, strict=True)
        if t.arm == "baseline"
    }
    out = []
    for p, v in points:
        study = _with(short, p, v)
        k = arm_of[(study.persons_per_hour, study.controller.sct_safe, study.penetration)]
        sb = summarise(study, [base[study.persons_per_hour]])[0]
        ss = summarise(study, [results[k]])[1]
        out.append(
            SensitivityPoint(
                p,
                v,
                sb.incidents,
                ss.incidents,
                reduction(sb.incidents, ss.incidents),
                ss.mean_travel_time - sb.mean_travel_time,
            )
        )
    return out


def _main(config: StudyConfig, parameter: str) -> float:
    if parameter == "sct_safe":
        return config.controller.sct_safe
    return float(getattr(config, parameter))
