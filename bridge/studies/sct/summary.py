"""The pedestrian incident study summed up: per variant and arm, counts and trip statistics
over all runs, and the incident reduction, beside the seed's own figures (no drawing here:
the report wing draws them)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.studies.sct.study import ARMS, ArmResult, StudyConfig

#: DIVP FY2020 report, C2 (divp-H §6.4): incidents over 2 days at 200 veh/h
SEED_BASELINE = 1990
SEED_SCT = 641
SEED_REDUCTION = (SEED_BASELINE - SEED_SCT) / SEED_BASELINE


@dataclass
class ArmSummary:
    """One arm of one variant, summed over its runs. Times in seconds."""

    variant: str
    arm: str
    sim_days: float
    vehicles: int
    encounters: int
    incidents: int
    ttc_incidents: int
    pet_incidents: int
    collisions: int
    mean_travel_time: float
    mean_time_loss: float
    mean_pedestrian_time_loss: float
    controller_interventions: int
    wall_seconds: float
    evaluated_share: float
    crashed_runs: int = 0  # runs whose worker process died: not in any figure above


def summarise(config: StudyConfig, results: list[ArmResult]) -> list[ArmSummary]:
    """Per (variant, arm): counts and trip statistics over all runs."""
    out = []
    ic = config.incidents
    for variant in config.variants:
        for arm in ARMS:
            rs = [r for r in results if r.variant == variant and r.arm == arm]
            inc = [e for r in rs for e in r.incidents]
            tt = np.concatenate([r.travel_time for r in rs]) if rs else np.zeros(0)
            tl = np.concatenate([r.time_loss for r in rs]) if rs else np.zeros(0)
            pl = np.concatenate([r.person_time_loss for r in rs]) if rs else np.zeros(0)
            out.append(
                ArmSummary(
                    variant=variant,
                    arm=arm,
                    sim_days=sum(r.sim_seconds for r in rs) / 86400.0,
                    vehicles=len(tt),
                    encounters=sum(len(r.encounters) for r in rs),
                    incidents=len(inc),
                    ttc_incidents=sum(e.min_ttc < ic.ttc_threshold for e in inc),
                    pet_incidents=sum(e.min_pet < ic.pet_threshold for e in inc),
                    collisions=sum(e.collision for e in inc),
                    mean_travel_time=_mean(tt),
                    mean_time_loss=_mean(tl),
                    mean_pedestrian_time_loss=_mean(pl),
                    controller_interventions=sum(r.interventions for r in rs),
                    wall_seconds=sum(r.wall_seconds for r in rs),
                    evaluated_share=sum(r.evaluated_steps for r in rs)
                    / max(sum(r.steps for r in rs), 1),
                    crashed_runs=sum(bool(r.crashed) for r in rs),
                )
            )
    return out


def _mean(a: np.ndarray) -> float:
    return float(a.mean()) if len(a) else math.nan


def pair(summaries: list[ArmSummary], variant: str) -> tuple[ArmSummary, ArmSummary]:
    base = next(s for s in summaries if s.variant == variant and s.arm == "baseline")
    sct = next(s for s in summaries if s.variant == variant and s.arm == "sct")
    return base, sct


def reduction(base: int, sct: int) -> float:
    """Relative reduction of incidents, (base - sct) / base (nan without baseline incidents)."""
    return (base - sct) / base if base else math.nan


def change_text(red: float) -> str:
    """The incident change for people ("-68%"), or why there is none."""
    return "n/a (no baseline incidents)" if math.isnan(red) else f"{-red:+.0%}"
