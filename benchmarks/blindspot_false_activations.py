"""AEB stages with no ground-truth conflict in the blind-spot set (issue 30, items 3 and 4).

Runs every realisable case (or those named) in closed loop with the sensor stack, one after the
other in this process, and counts the cases whose AEB reached a stage while the ground-truth
TTC to every actor stayed infinite over the whole run (no conflict at all), the full-brake
ones among them, the AEB braking episodes risk.metrics.false_braking calls false, and per case
the largest lateral-speed error of the truck's fused tracks (tracks whose truth is the truck,
ego frame, against the truck's true velocity): over the tracks the planner acts on (classified,
velocity observed: AEBConfig.max_velocity_sigma), the error issue 30 bounds, and over every
reported track, whose velocity right after birth is still the wide prior
(FusionConfig.velocity_prior_sigma) fitted to a few positions.

Run: .venv/bin/python benchmarks/blindspot_false_activations.py OUT.json [case,case,...]
(a measurement of the sensor stack, not a performance figure: kept beside the benchmarks)
"""

from __future__ import annotations

import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from hiyari.bridge.loop.stack.aeb import AEBConfig
from hiyari.bridge.studies.perception.blindspot.catalogue import combinations
from hiyari.bridge.studies.perception.blindspot.occlusion import OcclusionProbe
from hiyari.bridge.studies.perception.blindspot.road import write_road
from hiyari.bridge.studies.perception.blindspot.run import check_occlusion
from hiyari.bridge.studies.perception.blindspot.scenarios import build_scenario
from hiyari.traffic.world_state import WorldState

#: m/s: the planner acts on a track once its velocity is known this well
MAX_VELOCITY_SIGMA = AEBConfig().max_velocity_sigma


def measure(workdir: Path, only: list[str] | None = None) -> list[dict]:
    """One row per case: collision, least ground-truth TTC (s), highest AEB stage, false AEB
    braking episodes, largest |lateral-speed error| of the truck's tracks the planner acts on
    and of all its reported tracks, with that track's velocity sigma then (m/s)."""
    from hiyari.bridge.loop.execute import execute
    from hiyari.bridge.loop.spec import EgoSetup, import_road, model_spec
    from hiyari.bridge.loop.stack.interfaces import EgoStep

    cases = [c for c in combinations() if c.realisable and (not only or c.name in only)]
    probe = OcclusionProbe()
    nets: dict = {}
    rows = []
    for combo in cases:
        shift, _ = check_occlusion(combo, probe)
        if combo.geometry not in nets:
            xodr = write_road(combo.geometry, workdir / f"bs_{combo.geometry.name.lower()}.xodr")
            net = import_road(build_scenario(combo, xodr, shift), workdir / "roads")
            nets[combo.geometry] = (xodr, net)
        xodr, net = nets[combo.geometry]
        lateral: list[tuple[float, float]] = []  # (error m/s, the track's velocity sigma m/s)
        acted: list[float] = []

        def on_step(
            world: WorldState,
            step: EgoStep,
            collisions: list,
            lateral: list[tuple[float, float]] = lateral,
            acted: list[float] = acted,
        ) -> None:
            ego = world.pose(int(np.flatnonzero(world.ids == "Ego")[0]))
            tracks = step.tracks
            sigma = tracks.velocity_sigma
            for k in np.flatnonzero(tracks.truth == "Occluder"):
                truck = world.pose(int(np.flatnonzero(world.ids == "Occluder")[0]))
                true_vy = ego.world_to_vehicle_vec(truck.velocity)[1]
                error = abs(float(tracks.velocity[k, 1] - true_vy))
                lateral.append((error, float(sigma[k]) if sigma is not None else float("nan")))
                if tracks.cls[k] >= 0 and (sigma is None or sigma[k] <= MAX_VELOCITY_SIGMA):
                    acted.append(error)

        spec = model_spec(build_scenario(combo, xodr, shift), EgoSetup(perception="sensors"), net)
        res = execute(spec, on_step=on_step)
        rows.append(
            dict(
                case=combo.name,
                collision=res.collision,
                min_ttc_s=res.min_ttc,
                aeb_max_stage=res.aeb_max_stage,
                false_aeb_brakings=res.false_braking()["aeb"].events,
                truck_lateral_error_max_mps=max(acted, default=0.0),
                truck_lateral_error_any_track_max_mps=max(lateral, default=(0.0, 0.0))[0],
                truck_lateral_error_any_track_sigma_mps=max(lateral, default=(0.0, 0.0))[1],
            )
        )
    return rows


def summary(rows: list[dict]) -> dict:
    """Counts over the cases: AEB stage (and full brake) with no ground-truth conflict."""
    no_conflict = [
        r
        for r in rows
        if r["aeb_max_stage"] >= 1 and not math.isfinite(r["min_ttc_s"]) and not r["collision"]
    ]
    return {
        "cases": len(rows),
        "aeb_stage_no_conflict": len(no_conflict),
        "full_brake_no_conflict": sum(r["aeb_max_stage"] == 3 for r in no_conflict),
        "false_aeb_cases": sum(r["false_aeb_brakings"] > 0 for r in rows),
        "collisions": [r["case"] for r in rows if r["collision"]],
        "no_conflict_cases": [r["case"] for r in no_conflict],
        "truck_lateral_error_max_mps": max(
            (r["truck_lateral_error_max_mps"] for r in rows), default=0.0
        ),
        "lateral_error_over_0_3_cases": [
            r["case"] for r in rows if r["truck_lateral_error_max_mps"] > 0.3
        ],
    }


def main(argv: list[str]) -> None:
    only = argv[1].split(",") if len(argv) > 1 and argv[1] else None
    with tempfile.TemporaryDirectory(prefix="hiyari-blindspot-") as tmp:
        rows = measure(Path(tmp), only)
    doc = {"summary": summary(rows), "cases": rows}
    Path(argv[0]).write_text(json.dumps(doc, indent=1) + "\n")
    print(json.dumps(doc["summary"], indent=1))


if __name__ == "__main__":
    main(sys.argv[1:])
