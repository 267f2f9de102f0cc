"""Kinematic sketches of a combination over its parameter probes: the ego without any
reaction and the surrounding vehicles doing the named motion, as (K, T) arrays of footprint
centres and headings (K probes, T times). The obstruction test runs on these.

Motorway: road coordinates are world coordinates (the generated road is straight along +x).
Intersection: paths through the junction of hiyari.net.road.xodr_writer (straight lines and
quarter arcs; a U-turn is a half circle from the inbound to the outbound lane).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.studies.catalogue.space.layout import BEHIND, MotorwayLayout
from hiyari.bridge.studies.catalogue.space.taxonomy import EgoMotion, Motion, Position
from hiyari.net.road.xodr_writer import LEGS
from hiyari.units import kmh_to_mps

#: Annex G sizes: ego 4.8 m x 1.9 m, others 5.3 m x 1.9 m.
EGO_SIZE = (4.8, 1.9)
OTHER_SIZE = (5.3, 1.9)
HORIZON = 12.0  # s
DT = 0.1  # s
#: Speed an accelerating vehicle stops accelerating at, above its start speed, m/s.
ACCEL_SPAN = kmh_to_mps(40.0)
#: Lateral shift of a swerve toward the ego's lane, m.
SWERVE_SHIFT = 1.2


@dataclass(frozen=True)
class Track:
    """(K, T) centre x, y (m) and heading (rad) of one vehicle over the probes."""

    x: np.ndarray
    y: np.ndarray
    h: np.ndarray
    length: float
    width: float


def times() -> np.ndarray:
    return np.arange(0.0, HORIZON + 1e-9, DT)


def longitudinal(v0: np.ndarray, accel: np.ndarray, t_event: float, v_cap: np.ndarray,
                 t: np.ndarray) -> np.ndarray:  # fmt: skip
    """(K, T) distance travelled (m) from speed ``v0`` with ``accel`` from ``t_event`` on,
    speed held within [0, v_cap]."""
    dt_on = np.clip(t[None, :] - t_event, 0.0, None)
    v = np.clip(v0[:, None] + accel[:, None] * dt_on, 0.0, v_cap[:, None])
    dist = np.concatenate([np.zeros((len(v0), 1)), np.cumsum(0.5 * (v[:, 1:] + v[:, :-1]), 1)], 1)
    return dist * DT


def lateral(y0: float, y1: float, vy: np.ndarray, t_event: float, t: np.ndarray) -> np.ndarray:
    """(K, T) lateral position moving from ``y0`` to ``y1`` at ``vy`` m/s from ``t_event``."""
    step = np.clip((t[None, :] - t_event) * vy[:, None], 0.0, abs(y1 - y0))
    return y0 + math.copysign(1.0, y1 - y0) * step


def _heading(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Heading along the velocity (Annex G), forward differences, rad."""
    dx = np.diff(x, axis=1, append=x[:, -1:] + (x[:, -1:] - x[:, -2:-1]))
    dy = np.diff(y, axis=1, append=y[:, -1:] + (y[:, -1:] - y[:, -2:-1]))
    moving = np.hypot(dx, dy) > 1e-6
    return np.where(moving, np.arctan2(dy, dx), 0.0)


def motorway_ego(layout: MotorwayLayout, p: dict[str, np.ndarray], ego_vy: float,
                 t_ego: float) -> Track:  # fmt: skip
    """The ego at constant speed in its lane, changing lanes when its motion says so."""
    t = times()
    v = p["ego_speed"]
    x = layout.start + longitudinal(v, np.zeros_like(v), 0.0, v, t)
    y0, y1 = layout.centre_t(layout.ego_lane), layout.centre_t(layout.ego_target)
    y = lateral(y0, y1, np.full_like(v, ego_vy), t_ego, t)
    return Track(x, y, _heading(x, y), *EGO_SIZE)


def motorway_actor(layout: MotorwayLayout, position: Position, motion: Motion,
                   p: dict[str, np.ndarray], t_event: float,
                   moving: bool = True) -> list[Track]:  # fmt: skip
    """The surrounding vehicle (and, for a cut-out from ahead of the ego, the stopped or
    slower "+1" ahead of it in its original lane, which the cut-out reveals). Empty when the
    motion is undefined at that position. ``moving`` False: the vehicle keeps its lane and
    speed instead (the counterfactual of the obstruction test; no "+1")."""
    t = times()
    lane = layout.lane_of(position)
    target, _ = layout.target_lane(position, motion)
    if lane is None or target is None:
        return []
    ve = p["ego_speed"]
    v0 = np.maximum(ve + p.get("speed_delta", 0.0), 0.5)
    le, la = EGO_SIZE[0], OTHER_SIZE[0]
    gap = p["lead_thw"] * ve if "lead_thw" in p else p["gap"]
    if position in BEHIND:
        x0 = layout.start - 0.5 * le - gap - 0.5 * la
    else:
        x0 = layout.start + 0.5 * le + gap + 0.5 * la
    accel = {Motion.ACCELERATE: p.get("accel"), Motion.DECELERATE: -p.get("decel", 0.0)}.get(motion)
    accel = np.zeros_like(ve) if accel is None or not moving else accel
    x = x0[:, None] + longitudinal(v0, accel, t_event, v0 + ACCEL_SPAN, t)
    y0 = layout.centre_t(lane)
    if not moving:
        y1 = y0
    elif motion == Motion.SWERVE:
        y1 = y0 + math.copysign(SWERVE_SHIFT, layout.centre_t(layout.ego_lane) - y0 or 1.0)
    else:
        y1 = layout.centre_t(target)
    vy = p.get("lateral_speed", np.ones_like(ve))
    y = lateral(y0, y1, vy, t_event, t)
    tracks = [Track(x, y, _heading(x, y), *OTHER_SIZE)]
    if moving and motion == Motion.CUT_OUT and position not in BEHIND:
        v1 = p.get("plus_one_speed", np.zeros_like(ve)) * ve
        x1 = x0 + 0.5 * la + p["plus_one_gap"] + 0.5 * la
        xp = x1[:, None] + longitudinal(v1, np.zeros_like(ve), 0.0, v1, t)
        yp = np.full_like(xp, y0)
        tracks.append(Track(xp, yp, _heading(xp, yp), *OTHER_SIZE))
    return tracks


# ------------------------------------------------------------------ intersection
#: Where each intersection position comes from (its inbound leg), the ego from the west.
SOURCE = {
    Position.FRONT: "west",
    Position.REAR: "west",
    Position.CROSSING_LEFT: "north",
    Position.CROSSING_RIGHT: "south",
    Position.ONCOMING: "east",
}
_TURN = {"straight": math.pi, "turn left": -math.pi / 2, "turn right": math.pi / 2, "U-turn": 0.0}


def destination(source: str, manoeuvre: str) -> str:
    """The leg a vehicle from ``source`` leaves by after ``manoeuvre`` (straight, turn
    left / right, U-turn)."""
    h = LEGS[source] + _TURN[manoeuvre]
    return min(LEGS, key=lambda k: abs(math.remainder(LEGS[k] - h, 2 * math.pi)))


def route_pose(source: str, dest: str, d: np.ndarray, approach: float,
               w: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """x, y, heading at distance ``d`` (m) along the route from ``source`` to ``dest``;
    d = 0 where it enters the junction (negative: still on the approach)."""
    hl = LEGS[source]
    h_in = hl + math.pi
    u = np.array([math.cos(h_in), math.sin(h_in)])
    n = np.array([-u[1], u[0]])
    entry = approach * np.array([math.cos(hl), math.sin(hl)]) - 0.5 * w * n
    turn = math.remainder(LEGS[dest] - h_in, 2 * math.pi) if source != dest else math.pi
    if abs(turn) < 1e-9:
        k, length = 0.0, 2 * approach
    else:
        r = 0.5 * w if source == dest else (approach + math.copysign(0.5 * w, turn))
        k, length = math.copysign(1.0 / r, turn), r * abs(turn)
    dc = np.clip(d, 0.0, length)
    if k == 0.0:
        along, across = dc, np.zeros_like(dc)
    else:
        along, across = np.sin(k * dc) / k, (1 - np.cos(k * dc)) / k
    x = entry[0] + along * u[0] + across * n[0]
    y = entry[1] + along * u[1] + across * n[1]
    h = h_in + k * dc
    before, after = np.minimum(d, 0.0), np.maximum(d - length, 0.0)
    x = x + before * u[0] + after * np.cos(h)
    y = y + before * u[1] + after * np.sin(h)
    return x, y, h


def intersection_track(source: str, manoeuvre: str, d0: np.ndarray, v0: np.ndarray,
                       accel: np.ndarray, t_event: float, approach: float, w: float,
                       size: tuple[float, float]) -> Track:  # fmt: skip
    """A vehicle starting ``d0`` m along its route (negative: before the junction)."""
    t = times()
    d = d0[:, None] + longitudinal(v0, accel, t_event, v0 + ACCEL_SPAN, t)
    x, y, h = route_pose(source, destination(source, manoeuvre), d, approach, w)
    return Track(x, y, h, *size)


EGO_MANOEUVRE = {
    EgoMotion.LANE_KEEP: "straight",
    EgoMotion.TURN_LEFT: "turn left",
    EgoMotion.TURN_RIGHT: "turn right",
}
