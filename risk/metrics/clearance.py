"""Near misses: the smallest lateral clearance between the ego and each road user it passes.

A run without contact can still have passed a pedestrian at 60 km/h a quarter of a metre
away; the tool is named for such events (hiyari: a near miss). Passing: the other's footprint
overlaps the ego's length along the ego's heading (its extent along the ego's axis, at its
own heading: hiyari.kinematics.footprint_extent) while the ego moves. The clearance then is
the shortest distance between the two footprints (kinematics.footprint_distance). A near miss
is a smallest clearance below a limit that grows with the ego's speed and is larger for
vulnerable road users (docs/models.md §4, "Near misses"): ``limit = base + gain * speed``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hiyari.kinematics import footprint_distance, footprint_extent, unrotate, wrap_angle
from hiyari.risk.metrics.ground_truth import TruthConfig, time_to_collision
from hiyari.traffic.actor_class import ActorClass

#: Actor classes taken as vulnerable road users (unprotected: EU ITS Directive 2010/40/EU's
#: definition, which includes powered two-wheelers).
VRU_CLASSES = (ActorClass.PEDESTRIAN, ActorClass.BICYCLE, ActorClass.MOTORCYCLE)


@dataclass(frozen=True)
class NearMissRule:
    """Clearance limits ``base + gain * ego speed`` (m, s) per kind of road user."""

    #: m: near-miss limit to a vulnerable road user at walking pace (the ego crawling past a
    #: pedestrian within half a metre leaves no room for a misjudged step).
    vru_base: float = 0.5
    #: s: added metres per m/s of ego speed for VRUs: 1.6 m at 50 km/h and 1.8 m at 60 km/h,
    #: near the passing distances the German StVO §5(4) prescribes for overtaking cyclists and
    #: pedestrians (1.5 m in town, 2 m outside).
    vru_gain: float = 0.08
    #: m: near-miss limit to another vehicle at low speed (mirrors almost touching).
    vehicle_base: float = 0.2
    #: s: added metres per m/s of ego speed for vehicles: 0.5 m at 30 m/s (108 km/h), about
    #: a third of the 1.6 m two cars keep side by side in 3.5 m lanes; a lane-keeping error
    #: that large at that speed is a near miss.
    vehicle_gain: float = 0.01
    #: m/s: below this ego speed nothing is passed (standing beside a car in a queue is not
    #: a near miss).
    min_speed: float = 1.0

    def limit(self, vru: bool, speed: float) -> float:
        """The clearance (m) under which passing at ego ``speed`` (m/s) is a near miss."""
        if vru:
            return self.vru_base + self.vru_gain * speed
        return self.vehicle_base + self.vehicle_gain * speed


@dataclass
class Passing:
    """The closest pass of one actor: clearance (m), the ego's speed then (m/s), the time
    (s), whether it is a VRU, the near-miss limit at that speed (m), and whether at some
    step the clearance was below the limit at that step's speed (``near_miss``)."""

    actor: str
    vru: bool
    clearance: float = float("inf")
    speed: float = 0.0
    time: float = float("nan")
    limit: float = 0.0
    near_miss: bool = False


@dataclass
class PassingClearances:
    """Per actor, the closest pass so far (update once per step)."""

    rule: NearMissRule = field(default_factory=NearMissRule)
    passes: dict[str, Passing] = field(default_factory=dict)

    def update(
        self,
        time: float,
        ids: np.ndarray,
        cls: np.ndarray,
        xy: np.ndarray,
        heading: np.ndarray,
        length: np.ndarray,
        width: np.ndarray,
        ego: int,
        ego_speed: float,
    ) -> None:
        """Take this step's state (a WorldState's columns, world m and rad; ``ego`` its row,
        ``ego_speed`` m/s)."""
        if ego_speed < self.rule.min_speed or len(ids) < 2:
            return
        xy = np.asarray(xy, float)
        h0 = float(heading[ego])
        rel = unrotate(xy - xy[ego], h0)
        ext_x, _ = footprint_extent(length, width, wrap_angle(np.asarray(heading) - h0))
        beside = np.abs(rel[:, 0]) <= ext_x + length[ego] / 2
        beside[ego] = False
        rows = np.flatnonzero(beside)
        if not len(rows):
            return
        gap = footprint_distance(
            xy[ego], h0, length[ego], width[ego], xy[rows], heading[rows], length[rows],
            width[rows],
        )  # fmt: skip
        for k, d in zip(rows.tolist(), gap.tolist(), strict=True):
            name = str(ids[k])
            p = self.passes.get(name)
            if p is None:
                p = self.passes[name] = Passing(name, int(cls[k]) in VRU_CLASSES)
            limit = self.rule.limit(p.vru, ego_speed)
            p.near_miss |= d < limit
            if d < p.clearance:
                p.clearance, p.speed, p.time, p.limit = d, ego_speed, time, limit

    def near_misses(self, exclude: str = "") -> list[Passing]:
        """The passes that were near misses (``exclude``: an actor hit, whose contact is a
        collision, not a near miss), by actor id."""
        return [p for name, p in sorted(self.passes.items()) if p.near_miss and name != exclude]


def near_miss_time(
    xy: np.ndarray,
    heading: np.ndarray,
    speed: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    cls: np.ndarray,
    ego: int,
    rule: NearMissRule = NearMissRule(),
    truth: TruthConfig | None = None,
) -> float:
    """Ground truth: the first time (s) at which some actor comes within its near-miss limit
    (``rule.limit`` at the ego's speed, by whether it is a VRU) of the ego's sides, everybody
    keeping their velocities: the TTC to the ego's footprint widened by that limit on each
    side (risk.metrics.ground_truth.time_to_collision). inf when none does within
    ``truth.horizon`` or the ego is slower than ``rule.min_speed`` (nothing is passed).
    Arrays as a WorldState's columns (world m, rad, m/s); ``ego`` its row.

    Where this is finite, braking answers a hazard ground truth holds: passing there would be
    a near miss (docs/models.md §4, "False activations")."""
    v_ego = float(speed[ego])
    if v_ego < rule.min_speed or len(xy) < 2:
        return float("inf")
    vru = np.isin(np.asarray(cls), VRU_CLASSES)
    margin = np.where(vru, rule.limit(True, v_ego), rule.limit(False, v_ego))
    truth = truth or TruthConfig()
    return float(time_to_collision(xy, heading, speed, length, width, ego, truth, margin).min())
