"""Ground-truth metrics of one actor (the ego) against everybody else at one time step.

Plain arrays in, arrays out (a WorldState's columns: world metres, radians CCW from +x, m/s),
so any closed loop can call it. Built on hiyari.kinematics:

- Time to collision (TTC): the first time at which an actor's footprint overlaps the ego's,
  both keeping their current velocity; each footprint heads along its velocity (an actor slower
  than ``min_speed`` is taken as aligned with the ego); slab test on the ego's axes
  (kinematics.footprint_entry_time). TTCs beyond ``horizon`` count as none (inf).
- Gap: bumper to bumper along the ego's heading to one actor, both taken aligned with the
  ego, and the side-to-side clearance (>= 0: the actor is beside the ego).
- Path headway: the ego's time headway (bumper gap / ego speed) behind the nearest actor ahead
  in its path, or entering it (a car cutting in): what following braking answers to, while
  the constant-velocity TTC of a car still moving sideways can be infinite.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.kinematics import bumper_gap, footprint_entry_time, heading_vector, unrotate, wrap_angle


@dataclass(frozen=True)
class TruthConfig:
    """``horizon`` s: longer TTCs are inf; ``min_speed`` m/s: slower actors are taken as
    aligned with the ego (their heading along velocity is undefined)."""

    horizon: float = 10.0
    min_speed: float = 0.5
    #: m: an actor ahead whose side-to-side clearance to the ego is below this is in its path
    path_margin: float = 0.5
    #: s: an actor moving sideways toward the ego counts as in its path this long before it is
    entry_time: float = 1.0


def time_to_collision(
    xy: np.ndarray,
    heading: np.ndarray,
    speed: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    ego: int,
    config: TruthConfig = TruthConfig(),
    margin: float | np.ndarray = 0.0,
) -> np.ndarray:
    """(N,) TTC (s) of each of N actors with actor ``ego`` (inf for the ego itself).

    ``xy`` (N, 2) ground-rectangle centres, ``heading`` (N,) rad, ``speed`` (N,) m/s along
    the heading, ``length`` / ``width`` (N,) m; ``margin`` (scalar or (N,)) m added to each
    side of the ego's width against each actor (0: contact).
    """
    xy = np.asarray(xy, float)
    vel = np.asarray(speed, float)[:, None] * heading_vector(heading)
    h0 = float(heading[ego])
    rel_pos = unrotate(xy - xy[ego], h0)
    rel_vel = unrotate(vel - vel[ego], h0)
    moving = np.asarray(speed) > config.min_speed
    rel_heading = np.where(moving, wrap_angle(np.asarray(heading) - h0), 0.0)
    ego_width = width[ego] + 2.0 * np.asarray(margin, float)
    ttc = footprint_entry_time(rel_pos, rel_vel, rel_heading, length[ego], ego_width, length, width)
    ttc = np.where(ttc <= config.horizon, ttc, np.inf)
    ttc[ego] = np.inf
    return ttc


def gap_to(
    xy: np.ndarray,
    heading: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    ego: int,
    other: int,
) -> tuple[float, float]:
    """(longitudinal, lateral) gap (m) from actor ``ego`` to actor ``other`` in the ego's
    frame (kinematics.bumper_gap): longitudinal is the other's rear minus the ego's front
    (negative when it is not ahead with clearance), lateral >= 0 when it is beside the ego."""
    rel = unrotate(np.asarray(xy[other], float) - xy[ego], float(heading[ego]))
    along, across = bumper_gap(rel, length[ego], width[ego], length[other], width[other])
    return float(along), float(across)


def path_headway(
    xy: np.ndarray,
    heading: np.ndarray,
    speed: np.ndarray,
    length: np.ndarray,
    width: np.ndarray,
    ego: int,
    config: TruthConfig = TruthConfig(),
) -> float:
    """The ego's time headway (s) behind the nearest actor ahead in its path: bumper gap /
    ego speed (both taken aligned with the ego). An actor is in the path when its
    side-to-side clearance to the ego is below ``config.path_margin``, now or within
    ``config.entry_time`` at its sideways speed toward the ego. inf when there is none or the
    ego stands still. Arrays as :func:`time_to_collision`."""
    xy = np.asarray(xy, float)
    v_ego = float(speed[ego])
    if v_ego <= 0.0 or len(xy) < 2:
        return float("inf")
    h0 = float(heading[ego])
    rel = unrotate(xy - xy[ego], h0)
    vel = unrotate(np.asarray(speed, float)[:, None] * heading_vector(heading), h0)
    along, across = bumper_gap(rel, length[ego], width[ego], np.asarray(length), np.asarray(width))
    toward = np.maximum(-np.sign(rel[:, 1]) * vel[:, 1], 0.0)  # sideways speed toward the ego
    in_path = across - toward * config.entry_time < config.path_margin
    ahead = in_path & (along >= 0.0)
    ahead[ego] = False
    return float(along[ahead].min() / v_ego) if ahead.any() else float("inf")
