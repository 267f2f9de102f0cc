"""Parameters of the competent and careful (C&C) human driver model and of the Annex G world.

Sources: JAMA framework 2.3.3.1 (driver timings and braking), JAMA Annex G (road, vehicle
sizes, other-vehicle behaviour) and the toolkit's own defaults where both are silent
(../shared/spec/MODELS.md §1). Every value the model uses is a field of :class:`CCParams`.

Frames and geometry (Annex G, G.5.6):

- a straight road of two lanes, ``lane_width_m`` = 3.5 m each, μ = 1.0, no slope;
- x along the road (m, forward), y lateral (m, left positive), the ego lane centre at y = 0
  and the adjacent lane centre at y = +lane_width_m (SUMO lane index 0 is the ego lane,
  index 1 the lane to its left);
- every vehicle is a ground rectangle aligned with the lane: the ego ``ego_length_m`` x
  ``ego_width_m`` (default 4.8 m x 1.9 m, our choice: Annex G leaves it to the applicant),
  the others ``other_length_m`` x ``other_width_m`` = 5.3 m x 1.9 m (Annex G);
- all vehicles start centred in their lanes; the other vehicle's lateral motion is a step in
  lateral velocity at t = 0 and ends when it is centred in its target lane; its longitudinal
  speed stays at Vo0 (Annex G attachment 3). Its heading follows the velocity vector for the
  SUMO trajectories (:mod:`hiyari.risk.cc.trajectory`), but contact is judged on
  lane-aligned rectangles: the C&C evaluation, like the Annex G point-mass model, ignores the
  few centimetres a yawed rectangle's corners move.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from hiyari.errors import HiyariError
from hiyari.units import G


@dataclass(frozen=True)
class CCParams:
    """Every parameter of the C&C driver model, its AEB variant and the Annex G world.

    Times in s, distances in m, decelerations in g (multiples of ``g_mps2``).
    """

    g_mps2: float = G
    """Standard gravity used to turn g into m/s² (MODELS.md §1)."""

    # -- perception and judgement (JAMA 2.3.3.1.1-3) --
    perception_time_s: float = 0.4
    """Risk perception: from cut-in / cut-out judgement (or the lead's brake onset) to danger
    judgement (JAMA: 0.4 s, driving-simulator study)."""
    wander_m: float = 0.375
    """Lateral displacement from its own lane centre at which a vehicle moving toward (cut-in)
    or away from (cut-out) the ego lane is judged to change lanes (UN R157 practice; JAMA
    gives it only in a lost figure)."""
    danger_lateral_m: float = 0.72
    """Extra lateral travel beyond ``wander_m`` that marks danger in the position-based
    judgement: maximum lateral velocity 1.8 m/s x 0.4 s (JAMA)."""
    judgement: str = "time"
    """``"time"``: danger judgement = lane-change judgement + ``perception_time_s``;
    ``"position"``: when the lateral displacement reaches ``wander_m + danger_lateral_m``.
    The two agree at Vy = 1.8 m/s (MODELS.md default: time-based)."""
    ttc_brake_s: float = 2.0
    """Cut-in only: braking is needed while TTC = gap / (Ve - Vo) < this; when TTC is larger
    at danger judgement the reaction starts when TTC first falls to it (JAMA: 2.0 s, UN
    collision-warning guideline; the rule is MODELS.md's)."""

    # -- braking (JAMA Fig. 9 left) --
    reaction_delay_s: float = 0.75
    """From danger judgement to the start of braking force (JAMA: 0.75 s)."""
    max_decel_g: float = 0.774
    """Maximum deceleration of a trained driver (JAMA: 0.774 g)."""
    ramp_time_s: float = 0.6
    """Time of the linear ramp from 0 to ``max_decel_g`` (JAMA: 0.6 s); the deceleration is
    then held until the ego no longer closes on the obstacle (cut-in: ego speed = Vo0;
    cut-out and deceleration: standstill)."""

    # -- AEB-equipped variant (JAMA Fig. 9 right; values are MODELS.md's) --
    aeb: bool = False
    """Add the AEB: ego deceleration = max(driver, AEB) once the AEB triggers."""
    aeb_ttc_s: float = 2.0
    """AEB trigger: TTC = gap / closing speed below this while the obstacle overlaps the ego
    laterally (cut-in: the other is inside the ego's width; cut-out: the stopped vehicle is
    revealed, the lead no longer overlapping the ego)."""
    aeb_delay_s: float = 0.0
    """From the AEB trigger to its braking force (no perception delay)."""
    aeb_decel_g: float = 0.85
    """AEB maximum deceleration."""
    aeb_ramp_time_s: float = 0.6
    """Time of the AEB's linear ramp to ``aeb_decel_g``."""

    # -- following gap in the cut-out and deceleration scenarios (JAMA 2.3.3.1.5.2-3) --
    thw_s: float = 2.0
    """Ego follows the lead at this time headway: dx0 = thw_s x Ve0 (lead speed = ego speed)."""

    # -- Annex G world --
    lane_width_m: float = 3.5
    road_mu: float = 1.0
    """Road friction; a lead deceleration above ``road_mu`` g is refused as unphysical."""
    ego_length_m: float = 4.8
    ego_width_m: float = 1.9
    other_length_m: float = 5.3
    other_width_m: float = 1.9
    max_heading_deg: float = 45.0
    """Feasibility of a lateral velocity: Vy <= Vo0 x tan(max_heading_deg). Annex G only says
    to exclude the physically impossible, e.g. Vy = 3 m/s at 10 km/h; 45° (Vy <= Vo0)
    excludes exactly that example."""

    contact_tol_m: float = 1e-6
    """Numerical tolerance: overlaps up to this are touching, not collisions, so that a
    scenario exactly on the Preventable boundary is Preventable."""

    def __post_init__(self) -> None:
        positive = [
            "g_mps2",
            "max_decel_g",
            "aeb_decel_g",
            "lane_width_m",
            "road_mu",
            "ego_length_m",
            "ego_width_m",
            "other_length_m",
            "other_width_m",
        ]
        non_negative = [
            "perception_time_s",
            "wander_m",
            "danger_lateral_m",
            "ttc_brake_s",
            "reaction_delay_s",
            "ramp_time_s",
            "aeb_ttc_s",
            "aeb_delay_s",
            "aeb_ramp_time_s",
            "thw_s",
            "contact_tol_m",
        ]
        for name in positive + non_negative:
            value = getattr(self, name)
            if not isinstance(value, int | float) or not math.isfinite(value):
                raise HiyariError(f"CCParams.{name} must be a finite number, got {value!r}")
            if name in positive and value <= 0:
                raise HiyariError(f"CCParams.{name} must be positive, got {value}")
            if value < 0:
                raise HiyariError(f"CCParams.{name} must not be negative, got {value}")
        if self.judgement not in ("time", "position"):
            raise HiyariError(
                f"CCParams.judgement must be 'time' or 'position', got {self.judgement!r}"
            )
        if not 0 < self.max_heading_deg < 90:
            raise HiyariError(
                f"CCParams.max_heading_deg must be in (0, 90), got {self.max_heading_deg}"
            )
        if self.cut_in_dy0_m <= 0:
            raise HiyariError(
                f"CCParams: vehicles of width {self.ego_width_m} m and {self.other_width_m} m "
                f"overlap in adjacent {self.lane_width_m} m lanes"
            )
        if self.wander_m >= self.lane_width_m:
            raise HiyariError(
                f"CCParams.wander_m ({self.wander_m} m) must be below the lane width "
                f"({self.lane_width_m} m)"
            )

    @property
    def max_decel_mps2(self) -> float:
        """Driver's maximum deceleration, m/s²."""
        return self.max_decel_g * self.g_mps2

    @property
    def aeb_decel_mps2(self) -> float:
        """AEB maximum deceleration, m/s²."""
        return self.aeb_decel_g * self.g_mps2

    @property
    def cut_in_dy0_m(self) -> float:
        """Initial lateral clearance dy0 between ego and the adjacent-lane vehicle (m)."""
        return self.lane_width_m - 0.5 * (self.ego_width_m + self.other_width_m)

    def danger_judgement_time(self, vy_mps: float | np.ndarray) -> float | np.ndarray:
        """Time (s) from the start of the lateral motion to danger judgement (array-friendly)."""
        if self.judgement == "time":
            return self.wander_m / vy_mps + self.perception_time_s
        return (self.wander_m + self.danger_lateral_m) / vy_mps

    def as_dict(self) -> dict[str, float | str | bool]:
        """All fields by name, for writing next to results."""
        return asdict(self)

    def with_overrides(self, overrides: list[str]) -> CCParams:
        """A copy with ``"name=value"`` overrides (as given on a command line) applied."""
        kinds = {f.name: type(getattr(self, f.name)) for f in fields(self)}
        changes: dict[str, object] = {}
        for item in overrides:
            name, sep, text = item.partition("=")
            name = name.strip()
            if not sep or name not in kinds:
                known = ", ".join(sorted(kinds))
                raise HiyariError(f"--param {item!r}: expected NAME=VALUE with NAME one of {known}")
            kind = kinds[name]
            if kind is bool:
                if text.lower() not in ("true", "false", "1", "0", "yes", "no"):
                    raise HiyariError(f"--param {name}: expected true or false, got {text!r}")
                changes[name] = text.lower() in ("true", "1", "yes")
            elif kind is str:
                changes[name] = text
            else:
                try:
                    changes[name] = float(text)
                except ValueError:
                    raise HiyariError(f"--param {name}: not a number: {text!r}") from None
        return replace(self, **changes)

    @classmethod
    def from_dict(cls, data: dict) -> CCParams:
        """Inverse of :meth:`as_dict`; unknown keys are refused."""
        names = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise HiyariError(f"CCParams: unknown parameter(s) {', '.join(unknown)}")
        return cls(**data)
