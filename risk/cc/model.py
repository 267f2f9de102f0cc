"""Parameters of the competent and careful (C&C) human driver model and of the Annex G world.

Sources: JAMA framework 2.3.3.1 (driver timings and braking), JAMA Annex G (road, vehicle
sizes, other-vehicle behaviour) and the toolkit's own defaults where both are silent
(docs/models.md §1). Every value the model uses is a field of :class:`CCParams`.

Frames and geometry (Annex G, G.5.6):

- a straight road of two lanes, ``lane_width_m`` = 3.5 m each, μ = 1.0, no slope;
- x along the road (m, forward), y lateral (m, left positive), the ego lane centre at y = 0
  and the adjacent lane centre at y = +lane_width_m (SUMO lane index 0 is the ego lane,
  index 1 the lane to its left);
- every vehicle is a ground rectangle: the ego ``ego_length_m`` x ``ego_width_m`` (default
  4.8 m x 1.9 m, our choice: Annex G leaves it to the applicant), the others
  ``other_length_m`` x ``other_width_m`` = 5.3 m x 1.9 m (Annex G);
- all vehicles start centred in their lanes; the other vehicle's lateral motion is a step in
  lateral velocity at t = 0 and ends when it is centred in its target lane; its longitudinal
  speed stays at Vo0 and its heading follows its velocity vector (Annex G attachment 3): a
  step to atan2(Vy, Vo0) at t = 0 and back to the lane heading when the lateral motion ends.
  With ``contact="heading"`` (default) contact is judged on the rectangles at those headings,
  as the closed loop moves them; ``contact="lane"`` keeps them aligned with the lane (the
  point-mass reading of Annex G, used by some public implementations).

Driver-model conventions (where the JAMA / R157 text leaves room; the defaults are
docs/models.md's and every alternative is a named value of a field below):

- ``judgement``: when the cut-in danger judgement fires: ``"time"`` (wander-zone exit +
  ``perception_time_s``), ``"position"`` (lateral displacement ``wander_m +
  danger_lateral_m``) or ``"overlap"`` (first lateral overlap with the ego);
- ``above_ttc``: when TTC at danger judgement is at or above ``ttc_brake_s``: ``"end"`` (not
  a critical cut-in: the scenario ends there; why it is the default: docs/models.md, "The
  cut-in that is not critical") or ``"wait"`` (react when TTC falls to it);
- ``cut_out_perception``: whether the cut-out danger judgement adds ``perception_time_s``;
- ``decel_perception``: ``"always"``, ``"never"`` or ``"hard-braking"`` (only when the lead
  brakes harder than ``hard_braking_mps2``).

In every convention a C&C driver whose danger judgement finds the other car already beside
it (longitudinal gap <= 0) does not brake for it: braking into a car alongside turns a pass
into a side collision.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from hiyari.errors import HiyariError
from hiyari.units import G

CONVENTIONS: dict[str, tuple] = {
    "judgement": ("time", "position", "overlap"),
    "above_ttc": ("end", "wait"),
    "cut_out_perception": (True, False),
    "decel_perception": ("always", "never", "hard-braking"),
    "contact": ("heading", "lane"),
}
"""The driver-model and geometry conventions and their allowed values (first = docs/models.md)."""


@dataclass(frozen=True)
class CCParams:
    """Every parameter of the C&C driver model, its AEB variant and the Annex G world.

    Times in s, distances in m, decelerations in g (multiples of ``g_mps2``).
    """

    g_mps2: float = G
    """Standard gravity used to turn g into m/s² (docs/models.md §1)."""

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
    """Cut-in danger judgement. ``"time"``: lane-change judgement + ``perception_time_s``;
    ``"position"``: when the lateral displacement reaches ``wander_m + danger_lateral_m`` (the
    two agree at Vy = 1.8 m/s); ``"overlap"``: at the first lateral overlap with the ego. In
    the cut-out, ``"overlap"`` reads as ``"time"`` (the stopped vehicle overlaps from the
    start). docs/models.md default: time-based."""
    above_ttc: str = "end"
    """Cut-in with TTC >= ``ttc_brake_s`` at danger judgement. ``"end"`` (default): the cut-in
    is not critical and the scenario ends at the danger judgement (contact before that still
    counts; docs/models.md says why); ``"wait"``: the reaction starts when TTC falls to it (at
    high relative speed then no gap is Preventable)."""
    cut_out_perception: bool = True
    """Cut-out: danger judgement = cut-out judgement + ``perception_time_s`` (docs/models.md);
    False: at the cut-out judgement itself (``"position"``: at ``wander_m``)."""
    decel_perception: str = "always"
    """Deceleration: ``"always"``: danger judgement ``perception_time_s`` after the lead's
    brake onset (docs/models.md); ``"never"``: at the onset; ``"hard-braking"``: the delay only
    when the lead decelerates harder than ``hard_braking_mps2`` (a public R157 reference
    driver's choice)."""
    hard_braking_mps2: float = 5.0
    """Threshold of ``decel_perception="hard-braking"``, m/s²."""
    contact: str = "heading"
    """Contact geometry of the cut-in: ``"heading"``: the other vehicle's rectangle turned
    along its velocity (Annex G attachment 3, as the closed loop moves it); ``"lane"``:
    aligned with the lane."""
    ttc_brake_s: float = 2.0
    """Cut-in only: braking is needed while TTC = gap / (Ve - Vo) < this; when TTC is larger
    at danger judgement the reaction starts when TTC first falls to it (JAMA: 2.0 s, UN
    collision-warning guideline; the rule is docs/models.md's)."""

    # -- braking (JAMA Fig. 9 left) --
    reaction_delay_s: float = 0.75
    """From danger judgement to the start of braking force (JAMA: 0.75 s)."""
    max_decel_g: float = 0.774
    """Maximum deceleration of a trained driver (JAMA: 0.774 g)."""
    ramp_time_s: float = 0.6
    """Time of the linear ramp from 0 to ``max_decel_g`` (JAMA: 0.6 s); the deceleration is
    then held until the ego no longer closes on the obstacle (cut-in: ego speed = Vo0;
    cut-out and deceleration: standstill)."""

    # -- AEB-equipped variant (JAMA Fig. 9 right; values are docs/models.md's) --
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
            "hard_braking_mps2",
        ]
        for name in positive + non_negative:
            value = getattr(self, name)
            if not isinstance(value, int | float) or not math.isfinite(value):
                raise HiyariError(f"CCParams.{name} must be a finite number, got {value!r}")
            if name in positive and value <= 0:
                raise HiyariError(f"CCParams.{name} must be positive, got {value}")
            if value < 0:
                raise HiyariError(f"CCParams.{name} must not be negative, got {value}")
        for name, allowed in CONVENTIONS.items():
            if getattr(self, name) not in allowed:
                choices = ", ".join(repr(a) for a in allowed)
                raise HiyariError(
                    f"CCParams.{name} must be one of {choices}, got {getattr(self, name)!r}"
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

    def lane_change_judgement_time(self, vy_mps: float | np.ndarray) -> float | np.ndarray:
        """Time (s) from the start of the lateral motion to the cut-in / cut-out judgement
        (displacement ``wander_m``), array-friendly."""
        return self.wander_m / vy_mps

    def danger_judgement_time(
        self, vy_mps: float | np.ndarray, t_overlap: float | np.ndarray | None = None
    ) -> float | np.ndarray:
        """Cut-in: time (s) from the start of the lateral motion to danger judgement
        (array-friendly); ``t_overlap`` (first lateral overlap, s) is needed for
        ``judgement="overlap"``."""
        if self.judgement == "time":
            return self.wander_m / vy_mps + self.perception_time_s
        if self.judgement == "position":
            return (self.wander_m + self.danger_lateral_m) / vy_mps
        if t_overlap is None:
            raise HiyariError("CCParams: judgement='overlap' needs the lateral overlap time")
        return t_overlap

    def cut_out_danger_time(self, vy_mps: float | np.ndarray) -> float | np.ndarray:
        """Cut-out: time (s) from the start of the lateral motion to danger judgement."""
        if not self.cut_out_perception:
            return self.wander_m / vy_mps
        if self.judgement == "position":
            return (self.wander_m + self.danger_lateral_m) / vy_mps
        return self.wander_m / vy_mps + self.perception_time_s

    def decel_danger_time(self, decel_mps2: float | np.ndarray) -> np.ndarray:
        """Deceleration: time (s) from the lead's brake onset to danger judgement."""
        decel = np.asarray(decel_mps2, dtype=float)
        if self.decel_perception == "always":
            return np.full(decel.shape, self.perception_time_s)
        if self.decel_perception == "never":
            return np.zeros(decel.shape)
        return np.where(decel > self.hard_braking_mps2, self.perception_time_s, 0.0)

    def conventions(self) -> dict[str, object]:
        """The convention fields by name (see :data:`CONVENTIONS`)."""
        return {name: getattr(self, name) for name in CONVENTIONS}

    def convention_note(self) -> str:
        """One line naming the conventions, for figure captions and reports."""
        danger = {
            "time": f"wander exit + {self.perception_time_s:g} s",
            "position": f"{self.wander_m + self.danger_lateral_m:g} m lateral",
            "overlap": "first lateral overlap",
        }[self.judgement]
        ttc = {"wait": "react when it falls", "end": "scenario ends"}[self.above_ttc]
        decel = {
            "always": f"+{self.perception_time_s:g} s",
            "never": "none",
            "hard-braking": f"+{self.perception_time_s:g} s above {self.hard_braking_mps2:g} m/s²",
        }[self.decel_perception]
        cut_out = f"+{self.perception_time_s:g} s" if self.cut_out_perception else "none"
        contact = {"heading": "along Annex G heading", "lane": "lane-aligned"}[self.contact]
        return (
            f"conventions: danger at {danger}; TTC ≥ {self.ttc_brake_s:g} s at danger: {ttc}; "
            f"perception delay cut-out {cut_out}, deceleration {decel}; contact {contact}"
            + ("" if self.is_models_default() else " (not the docs/models.md default)")
        )

    def is_models_default(self) -> bool:
        """True when every convention is docs/models.md's."""
        return all(getattr(self, n) == allowed[0] for n, allowed in CONVENTIONS.items())

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
