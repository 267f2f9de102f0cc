"""How a run of a scenario is scored besides its storyboard: the scored actor, the conflict
point and when a stopped ego ends the run."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Scoring:
    """How a run is scored and ended besides its storyboard. ``target``: the actor whose bumper
    gap is scored ('': the nearest actor ahead in the ego's corridor); ``conflict_point``:
    network x, y (m) whose distance ahead of the ego's front is recorded (None: none); the
    run ends ``settle_after_stop`` s after the ego first stands still (below 0.05 m/s) later
    than scenario time ``settle_from`` s (inf: never)."""

    target: str = ""
    conflict_point: tuple[float, float] | None = None
    settle_after_stop: float = math.inf
    settle_from: float = 0.0
