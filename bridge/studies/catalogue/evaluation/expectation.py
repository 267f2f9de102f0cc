"""The C&C expectation of each concrete case and the judgement of the stack's run.

Where the case is one of the Annex G types the C&C evaluator (hiyari.risk.cc) answers in
closed form: ego keeping its lane and the lead braking (deceleration), a vehicle from an
adjacent lane ahead, not faster than the ego, cutting in (cut-in), or the lead cutting out
in front of a stopped "+1" (cut-out). Its t = 0 is the manoeuvre start, so the initial gap is
advanced to it. Every other case is answered by running the C&C reference driver in the same
closed loop (hiyari.bridge.loop.drivers.cc_driver).

Judgement: Preventable = the C&C driver does not collide. Pass: no collision where it is
Preventable; elsewhere, no collision or an impact no harder than the C&C driver's
(relative impact speed within ``IMPACT_TOLERANCE``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from hiyari.bridge.studies.catalogue.space.concrete import ConcreteCase
from hiyari.bridge.studies.catalogue.space.sketch import EGO_SIZE
from hiyari.bridge.studies.catalogue.space.taxonomy import EgoMotion, Motion, Position
from hiyari.errors import HiyariError
from hiyari.risk.cc.evaluator import evaluate_cut_in, evaluate_cut_out, evaluate_decel
from hiyari.risk.cc.model import CCParams

#: Relative impact speed (m/s) by which an unpreventable collision may exceed the C&C
#: driver's and still be "no worse".
IMPACT_TOLERANCE = 1.0


@dataclass(frozen=True)
class Expectation:
    """What the C&C driver does in a case: ``collision``, relative ``impact_speed`` (m/s,
    0 without collision), ``source``: "annex-g:<type>" or "reference"."""

    collision: bool
    impact_speed: float
    source: str

    @property
    def preventable(self) -> bool:
        return not self.collision


def annex_g(case: ConcreteCase) -> Expectation | None:
    """The evaluator's answer when ``case`` is one of its types, else None."""
    c, pos, p = case.cell.combination, case.cell.position, case.params
    if c.ego != EgoMotion.LANE_KEEP or c.prefix == "C":
        return None
    params = dataclasses.replace(CCParams(), ego_length_m=EGO_SIZE[0])
    ve = p["ego_speed"]
    try:
        if c.motion == Motion.DECELERATE and pos == Position.FRONT:
            r = evaluate_decel(ve, p["decel"] / params.g_mps2, params, dx0_m=p["lead_thw"] * ve)
            kind = "deceleration"
        elif c.motion == Motion.CUT_OUT and pos == Position.FRONT:
            r = evaluate_cut_out(ve, p["lateral_speed"], p["plus_one_gap"],
                                 dataclasses.replace(params, thw_s=p["lead_thw"]))  # fmt: skip
            kind = "cut-out"
        elif c.motion == Motion.CUT_IN and pos in (Position.LEFT_FRONT, Position.RIGHT_FRONT):
            vo = ve + p["speed_delta"]
            dx0 = p["gap"] + (vo - ve) * case.ranges.event_time
            if vo > ve or dx0 < 0:
                return None
            r = evaluate_cut_in(ve, vo, dx0, p["lateral_speed"], params)
            kind = "cut-in"
        else:
            return None
    except HiyariError:
        return None  # outside the evaluator's domain (e.g. an infeasible lateral speed)
    if not bool(r.valid[0]):
        return None
    impact = float(r.impact_speed_mps[0])
    collided = bool(r.collision[0])
    return Expectation(collided, impact if collided and math.isfinite(impact) else 0.0,
                       f"annex-g:{kind}")  # fmt: skip


def judge(collision: bool, impact_speed: float, expected: Expectation) -> bool:
    """Pass / fail of the stack's run against the C&C expectation (module doc)."""
    if not collision:
        return True
    if expected.preventable:
        return False
    return impact_speed <= expected.impact_speed + IMPACT_TOLERANCE
