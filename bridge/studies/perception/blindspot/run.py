"""Run the blind-spot catalogue: occlusion check by ray cast, then closed loop, then verdict.

Per realisable combination: the hidden car's start is searched within its slot for the deepest
LiDAR occlusion (occlusion.py); the scenario (scenarios.py) runs in closed loop with the
sensor ego stack (ray-cast LiDAR, radar, camera, fusion, ACC + AEB) on the road of its geometry
(road.py, imported to SUMO once per geometry). Verdict: collision of the ego, else the least
ground-truth TTC. The closed-loop runs go to worker processes (the campaign pool): a run whose
worker dies (a native crash) is reported as crashed, the others go on.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from hiyari.bridge.studies.perception.blindspot.catalogue import Combination, Geometry, combinations
from hiyari.bridge.studies.perception.blindspot.occlusion import (
    HIDDEN_BELOW,
    OcclusionProbe,
    deepest_occlusion,
)
from hiyari.bridge.studies.perception.blindspot.road import write_road
from hiyari.bridge.studies.perception.blindspot.scenarios import (
    build_scenario,
    initial_world,
    shifts,
)
from hiyari.bridge.studies.pool import Crashed, PoolOptions, run_all


@dataclass(frozen=True)
class CaseResult:
    """One realisable combination, checked and run."""

    combo: Combination
    shift_m: float
    """Where in its slot the hidden car started, m from the slot centre."""
    visible_fraction: float
    """LiDAR returns on the hidden car with the truck over those without it, at the start."""
    collision: bool | None
    """None when the closed loop was not run."""
    min_ttc_s: float | None
    aeb_max_stage: int | None
    crashed: str = ""
    """Why the closed-loop run's worker process died ("": it did not; then collision is None)."""
    tested: bool | None = None
    """Whether the run tested its disturbance (hiyari.risk.metrics.tested); None: not run."""
    untested_cause: str = ""
    false_activations: int | None = None
    """AEB stages or hard braking with no ground-truth conflict (None: not run)."""
    near_misses: int | None = None

    @property
    def hidden(self) -> bool:
        """The ray cast confirms the occlusion at the start."""
        return self.visible_fraction < HIDDEN_BELOW


def check_occlusion(combo: Combination, probe: OcclusionProbe) -> tuple[float, float]:
    """(shift m, visible-ray fraction) of the deepest-occluded start of ``combo``."""
    cands = shifts(combo)
    best, fraction = deepest_occlusion(probe, [initial_world(combo, s) for s in cands])
    return cands[best], fraction


def _closed_loop(task: tuple[object, Path]) -> dict:
    """The CaseResult fields of one scenario run on its SUMO net."""
    from hiyari.bridge.loop.execute import execute
    from hiyari.bridge.loop.spec import EgoSetup, model_spec

    scenario, net = task
    res = execute(model_spec(scenario, EgoSetup(perception="sensors"), net))
    tested = res.tested()
    return {
        "collision": res.collision,
        "min_ttc_s": res.min_ttc,
        "aeb_max_stage": res.aeb_max_stage,
        "tested": tested.tested,
        "untested_cause": tested.reason,
        "false_activations": res.false_activations(),
        "near_misses": len(res.near_misses()),
    }


def run_catalogue(
    workdir: Path,
    closed_loop: bool = True,
    only: list[str] | None = None,
    progress: bool = True,
    pool: PoolOptions | None = None,
) -> list[CaseResult]:
    """Every realisable combination (or those named in ``only``): occlusion, then closed loop
    (in ``pool``'s worker processes; default: one per core)."""
    from tqdm import tqdm

    from hiyari.bridge.loop.spec import import_road

    cases = [c for c in combinations() if c.realisable and (not only or c.name in only)]
    probe = OcclusionProbe()
    checked = [(combo, *check_occlusion(combo, probe)) for combo in cases]
    out = [
        CaseResult(combo, shift, fraction, None, None, None) for combo, shift, fraction in checked
    ]
    if not closed_loop:
        return out
    nets: dict[Geometry, tuple[Path, Path]] = {}
    tasks = []
    for combo, shift, _ in checked:
        if combo.geometry not in nets:
            xodr = write_road(
                combo.geometry, workdir / f"blindspot_{combo.geometry.name.lower()}.xodr"
            )
            nets[combo.geometry] = (
                xodr,
                import_road(build_scenario(combo, xodr, shift), workdir / "roads"),
            )
        xodr, net = nets[combo.geometry]
        tasks.append((build_scenario(combo, xodr, shift), net))
    with tqdm(total=len(tasks), desc="blind-spot catalogue", disable=not progress) as bar:
        for i, res in run_all(_closed_loop, tasks, pool or PoolOptions()):
            if isinstance(res, Crashed):
                out[i] = replace(out[i], crashed=str(res))
            else:
                out[i] = replace(out[i], **res)
            bar.update(1)
    return out
