"""Logical parameter ranges of the catalogue's concrete scenarios and their sampling.

The JAMA text (§4.1) gives no ranges; these follow Annex G / UN R157 (JAMA Annex G) and docs/models.md:
ego speeds up to the design speed (130 km/h), lateral speeds up to the Annex G cut-in values,
decelerations up to the road's friction (mu = 1.0), Annex G vehicle sizes. Every value is a
field of :class:`Ranges`, so a user can run another interpretation. SI units inside.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.units import kmh_to_mps


@dataclass(frozen=True)
class Ranges:
    """Logical parameter ranges (low, high), SI units. ``gap``: clear longitudinal gap between
    the ego and the surrounding vehicle (front positions: ego front to its rear; rear
    positions: its front to the ego rear)."""

    ego_speed: tuple[float, float] = (kmh_to_mps(60.0), kmh_to_mps(120.0))
    #: actor speed minus ego speed for actors ahead (slower, Annex G cut-in) and behind (faster)
    ahead_speed_delta: tuple[float, float] = (kmh_to_mps(-30.0), 0.0)
    behind_speed_delta: tuple[float, float] = (kmh_to_mps(5.0), kmh_to_mps(30.0))
    gap: tuple[float, float] = (5.0, 40.0)
    lateral_speed: tuple[float, float] = (0.5, 2.0)  # m/s, cut-in / cut-out / swerve
    decel: tuple[float, float] = (0.3 * 9.81, 0.8 * 9.81)  # m/s^2, lead's braking
    accel: tuple[float, float] = (1.0, 3.0)  # m/s^2
    lead_thw: tuple[float, float] = (1.0, 2.0)  # s, ego behind its lead (cut-out, +1)
    plus_one_gap: tuple[float, float] = (20.0, 80.0)  # m, lead front to the +1's rear
    chain_plus_one_speed: tuple[float, float] = (0.2, 0.6)  # x ego speed, §4.1.3 slower +1
    ego_lateral_speed: float = 1.0  # m/s, the ego's own lane change
    event_time: float = 2.0  # s after the start: the surrounding vehicle's manoeuvre begins
    ego_event_time: float = 1.0  # s: the ego starts its lane change
    duration: float = 10.0  # s of simulation per concrete run
    #: intersection: approach speeds and the other vehicle's arrival at the junction entry
    #: relative to the ego's (s; crossing and oncoming positions)
    junction_speed: tuple[float, float] = (kmh_to_mps(20.0), kmh_to_mps(50.0))
    arrival_offset: tuple[float, float] = (-2.0, 2.0)
    junction_arrival: float = 4.0  # s: the ego reaches the junction entry

    def names(self, motion: str, lead: bool = False, chain: bool = False) -> tuple[str, ...]:
        """Parameters a concrete scenario with ``motion`` draws (order = columns). ``lead``:
        the surrounding vehicle is the ego's lead (front position): for a deceleration or a
        cut-out it drives at the ego's speed ``lead_thw`` ahead, as in Annex G."""
        if lead and motion in ("decelerate", "cut-out"):
            base: tuple[str, ...] = ("ego_speed", "lead_thw")
        else:
            base = ("ego_speed", "speed_delta", "gap")
        extra = {
            "accelerate": ("accel",),
            "decelerate": ("decel",),
            "cut-in": ("lateral_speed",),
            "cut-out": ("lateral_speed", "plus_one_gap"),
            "swerve": ("lateral_speed",),
        }.get(motion, ())
        return base + extra + (("plus_one_speed",) if chain else ())


def sample(ranges: Ranges, names: tuple[str, ...], behind: bool, n: int, seed: int) -> list[dict]:
    """``n`` concrete parameter sets drawn by a scrambled Sobol sequence over the ranges
    (deterministic for ``seed``): dicts name -> value (SI)."""
    from scipy.stats import qmc

    lows, highs = zip(*(_range(ranges, k, behind) for k in names), strict=True)
    m = max(n - 1, 1).bit_length()  # Sobol points are balanced in powers of two
    u = qmc.Sobol(len(names), scramble=True, seed=seed).random_base2(m)[:n]
    values = qmc.scale(u, lows, highs) if n else np.zeros((0, len(names)))
    return [dict(zip(names, map(float, row), strict=True)) for row in values]


def corners(ranges: Ranges, names: tuple[str, ...], behind: bool) -> dict[str, np.ndarray]:
    """Every corner and the centre of the range box: arrays name -> (K,), the probe set of the
    obstruction test."""
    bounds = np.array([_range(ranges, k, behind) for k in names])
    grids = np.meshgrid(*[np.array(b) for b in bounds], indexing="ij")
    probes = np.concatenate([np.stack([g.ravel() for g in grids], 1), bounds.mean(1)[None]])
    return {k: probes[:, i] for i, k in enumerate(names)}


def _range(ranges: Ranges, name: str, behind: bool) -> tuple[float, float]:
    if name == "speed_delta":
        return ranges.behind_speed_delta if behind else ranges.ahead_speed_delta
    if name == "plus_one_speed":
        return ranges.chain_plus_one_speed
    return getattr(ranges, name)
