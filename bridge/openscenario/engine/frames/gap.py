"""Where on the reference's road an actor is a given gap from its reference entity, the gap
measured in a LongitudinalDistanceAction's coordinate system: along the reference's heading
(entity: the projection of the actor's reference point on the reference's x axis) or along
the centre line of the reference's lane (lane). The road frame's gap is the s difference
itself. Solved by secant steps on the actor's road s, at its offset t across the road."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from hiyari.bridge.openscenario.engine.frames.lane import lane_length
from hiyari.bridge.openscenario.engine.positions import Pose

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine
    from hiyari.bridge.openscenario.engine.motion import Actor

#: Secant steps and the tolerance (m) they stop at.
STEPS, TOLERANCE = 12, 1e-9


def ref_length(engine: ScenarioEngine, ref: Pose) -> float:
    """Length (m) of the reference's road."""
    return engine.roads.odr.road(ref.road).length


def gap_s(engine: ScenarioEngine, ref: Pose, a: Actor, gap: float, system: str) -> float:
    """Road s (on ``ref``'s road) at which actor ``a`` (at its t) is ``gap`` m from the
    reference ``ref`` in ``system`` ("entity" or "lane"), signed along the road's s; the
    road-frame answer (``ref.s + gap``) where the road ends first."""
    odr = engine.roads.odr
    length = ref_length(engine, ref)

    def measure(s: float) -> float:
        if system == "lane":
            return lane_length(engine, ref.road, ref.lane, ref.s, s)
        x, y, _, _ = odr.road_pose(ref.road, np.array([s]), np.array([a.t]))
        return (x[0] - ref.x) * math.cos(ref.h) + (y[0] - ref.y) * math.sin(ref.h)

    # the entity frame's axis points along the reference's heading: against s when it
    # drives against s
    sign = 1.0 if system == "lane" or math.cos(ref.h - _road_heading(engine, ref)) >= 0 else -1.0
    want = sign * gap
    s0, s1 = ref.s + gap, ref.s + 1.01 * gap + 1e-3
    f0, f1 = measure(s0) - want, measure(s1) - want
    for _ in range(STEPS):
        if abs(f1) < TOLERANCE or f1 == f0:
            break
        s0, s1, f0 = s1, s1 - f1 * (s1 - s0) / (f1 - f0), f1
        if not 0.0 <= s1 <= length:
            return ref.s + gap
        f1 = measure(s1) - want
    return s1


def _road_heading(engine: ScenarioEngine, ref: Pose) -> float:
    """Heading (rad) of the reference line at the reference's s."""
    _, _, _, h = engine.roads.odr.road_pose(ref.road, np.array([ref.s]), np.array([0.0]))
    return float(h[0])
