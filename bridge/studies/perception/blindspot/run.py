"""Run the blind-spot catalogue: occlusion check by ray cast, then closed loop, then verdict.

Per realisable combination: the hidden car's start is searched within its slot for the deepest
LiDAR occlusion (occlusion.py); the scenario (scenarios.py) runs in closed loop with the
sensor ego stack (ray-cast LiDAR, radar, camera, fusion, ACC + AEB) on the road of its geometry
(road.py, imported to SUMO once per geometry). Verdict: collision of the ego, else the least
ground-truth TTC.
"""

from __future__ import annotations

from dataclasses import dataclass
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

    @property
    def hidden(self) -> bool:
        """The ray cast confirms the occlusion at the start."""
        return self.visible_fraction < HIDDEN_BELOW


def check_occlusion(combo: Combination, probe: OcclusionProbe) -> tuple[float, float]:
    """(shift m, visible-ray fraction) of the deepest-occluded start of ``combo``."""
    cands = shifts(combo)
    best, fraction = deepest_occlusion(probe, [initial_world(combo, s) for s in cands])
    return cands[best], fraction


def run_catalogue(
    workdir: Path,
    closed_loop: bool = True,
    only: list[str] | None = None,
    progress: bool = True,
) -> list[CaseResult]:
    """Every realisable combination (or those named in ``only``): occlusion, then closed loop."""
    from tqdm import tqdm

    from hiyari.bridge.loop.execute import execute
    from hiyari.bridge.loop.spec import EgoSetup, import_road, model_spec

    cases = [c for c in combinations() if c.realisable and (not only or c.name in only)]
    probe = OcclusionProbe()
    nets: dict[Geometry, tuple[Path, Path]] = {}
    out = []
    for combo in tqdm(cases, desc="blind-spot catalogue", disable=not progress):
        shift, fraction = check_occlusion(combo, probe)
        collision = ttc = stage = None
        if closed_loop:
            if combo.geometry not in nets:
                xodr = write_road(
                    combo.geometry, workdir / f"blindspot_{combo.geometry.name.lower()}.xodr"
                )
                sc0 = build_scenario(combo, xodr, shift)
                nets[combo.geometry] = (xodr, import_road(sc0, workdir / "roads"))
            xodr, net = nets[combo.geometry]
            sc = build_scenario(combo, xodr, shift)
            res = execute(model_spec(sc, EgoSetup(perception="sensors"), net))
            collision, ttc, stage = res.collision, res.min_ttc, res.aeb_max_stage
        out.append(CaseResult(combo, shift, fraction, collision, ttc, stage))
    return out
