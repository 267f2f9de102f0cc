"""The validity rule of JAMA §4.1.1.3 as a geometric test: a position x motion is kept only
when the motion can obstruct the ego's path.

Test: over the probes of the logical parameter ranges (every corner and the centre of the
range box), sketch the ego without reaction and the surrounding vehicle doing the motion
(hiyari.bridge.studies.catalogue.space.sketch), and look for the first overlap of their footprints
(hiyari.kinematics separating-axis test). The combination obstructs when, in some probe, the
motion makes an overlap that the same vehicle keeping its lane and speed would not make (the
motion is the cause), unless the overlap is the surrounding vehicle running into a
lane-keeping ego from behind (its own fault: the ego's path was never entered). The "+1" vehicle stands ahead of the lead,
which shields the ego from it; its motions reach the ego only through the lead's response,
i.e. as a §4.1.3 chain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.bridge.studies.catalogue.space.layout import BEHIND, MotorwayLayout
from hiyari.bridge.studies.catalogue.space.parameters import Ranges, corners
from hiyari.bridge.studies.catalogue.space.sketch import (
    EGO_MANOEUVRE,
    EGO_SIZE,
    OTHER_SIZE,
    SOURCE,
    Track,
    intersection_track,
    motorway_actor,
    motorway_ego,
)
from hiyari.bridge.studies.catalogue.space.taxonomy import (
    ADJACENT,
    INTERSECTION_POSITIONS,
    Combination,
    Geometry,
    Motion,
    Position,
)
from hiyari.kinematics import footprint_corners, overlap_depth, world_to_vehicle
from hiyari.net.road.xodr_writer import CatalogueRoad

#: Lateral displacement (m) below which the ego still counts as keeping its lane (the C&C
#: wandering threshold, docs/models.md).
WANDER = 0.375
LANE_COUNTS = (2, 3)


@dataclass(frozen=True)
class Cell:
    """One expansion of a combination: a surrounding position on a road with ``lanes``
    through lanes. ``status``: "obstructs" (evaluated), "no lane", "undefined",
    "non-obstructing", "shielded"; ``reason`` says why in one line."""

    combination: Combination
    position: Position
    lanes: int
    status: str
    reason: str

    @property
    def valid(self) -> bool:
        return self.status == "obstructs"

    @property
    def key(self) -> str:
        return f"{self.combination.key}-{self.position.name.lower()}-{self.lanes}L"


def first_contact(ego: Track, other: Track) -> tuple[np.ndarray, np.ndarray]:
    """(K,) whether the footprints ever overlap and the first overlapping time index."""
    reach = 0.5 * (np.hypot(ego.length, ego.width) + np.hypot(other.length, other.width))
    near = np.hypot(ego.x - other.x, ego.y - other.y) < reach  # bounding circles touch
    hit = np.zeros(ego.x.shape, bool)
    if near.any():
        ce = footprint_corners(
            np.stack([ego.x[near], ego.y[near]], -1), ego.h[near], ego.length, ego.width
        )
        co = footprint_corners(
            np.stack([other.x[near], other.y[near]], -1), other.h[near], other.length, other.width
        )
        hit[near] = overlap_depth(ce, co) > 0
    return hit.any(1), np.argmax(hit, 1)


def obstructs(ego: Track, others: list[Track], ego_lateral: np.ndarray) -> np.ndarray:
    """(K,) probes where a surrounding vehicle enters the ego's path (see module doc).
    ``ego_lateral`` (K, T): the ego's lateral displacement from its start path, m."""
    out = np.zeros(ego.x.shape[0], bool)
    rows = np.arange(ego.x.shape[0])
    for other in others:
        hit, i = first_contact(ego, other)
        centre = np.stack([ego.x[rows, i], ego.y[rows, i]], -1)
        rel = world_to_vehicle(
            np.stack([other.x[rows, i], other.y[rows, i]], -1), centre, ego.h[rows, i]
        )
        from_behind = (rel[:, 0] < -0.5 * ego.length) | (
            (rel[:, 0] < 0) & (np.abs(rel[:, 1]) < 0.5 * (ego.width + other.width))
        )
        kept_lane = np.abs(ego_lateral[rows, i]) < WANDER
        out |= hit & ~(from_behind & kept_lane)
    return out


def _motorway_cell(c: Combination, position: Position, lanes: int, ranges: Ranges) -> Cell:
    layout = MotorwayLayout(c.geometry, c.ego, lanes)
    if layout.lane_of(position) is None:
        side = "left" if "left" in position.value else "right"
        return Cell(c, position, lanes, "no lane", f"no lane to the {side} of the ego's lane")
    if position == Position.PLUS_ONE:
        why = "the lead shields the ego: its motion reaches the ego through the lead (§4.1.3 chain)"
        return Cell(c, position, lanes, "shielded", why)
    target, why = layout.target_lane(position, c.motion)
    if target is None:
        return Cell(c, position, lanes, "undefined", why)
    names = ranges.names(c.motion.value, position == Position.FRONT, c.prefix == "C")
    p = corners(ranges, names, position in BEHIND)
    ego = motorway_ego(layout, p, ranges.ego_lateral_speed, ranges.ego_event_time)
    others = motorway_actor(layout, position, c.motion, p, ranges.event_time)
    still = motorway_actor(layout, position, c.motion, p, ranges.event_time, moving=False)
    lateral = ego.y - ego.y[:, :1]
    hits = obstructs(ego, others, lateral) & ~obstructs(ego, still, lateral)
    if hits.any():
        share = f"{hits.sum()} of {len(hits)} range probes"
        return Cell(c, position, lanes, "obstructs", f"enters the ego's path in {share}")
    return Cell(c, position, lanes, "non-obstructing", "never enters the ego's path in the ranges")


def _intersection_cell(c: Combination, position: Position, ranges: Ranges) -> Cell:
    road = CatalogueRoad("intersection", 1)
    names = ("ego_speed", "other_speed", "offset")
    lo_hi = [ranges.junction_speed, ranges.junction_speed, ranges.arrival_offset]
    grids = np.meshgrid(*[np.array([lo, 0.5 * (lo + hi), hi]) for lo, hi in lo_hi], indexing="ij")
    p = {k: g.ravel() for k, g in zip(names, grids, strict=True)}
    zeros = np.zeros_like(p["ego_speed"])
    t_arr = ranges.junction_arrival
    ego_d0 = -p["ego_speed"] * t_arr
    ego = intersection_track("west", EGO_MANOEUVRE[c.ego], ego_d0, p["ego_speed"], zeros, 0.0,
                             road.approach, road.lane_width, EGO_SIZE)  # fmt: skip
    manoeuvre = {
        Motion.TURN_LEFT: "turn left",
        Motion.TURN_RIGHT: "turn right",
        Motion.U_TURN: "U-turn",
    }.get(c.motion, "straight")
    accel = {Motion.ACCELERATE: ranges.accel[1], Motion.DECELERATE: -ranges.decel[1]}.get(
        c.motion, 0.0
    )
    v = p["other_speed"]
    if position in (Position.FRONT, Position.REAR):
        sign = 1.0 if position == Position.FRONT else -1.0
        d0 = ego_d0 + sign * (0.5 * (EGO_SIZE[0] + OTHER_SIZE[0]) + ranges.gap[0])
        v = p["ego_speed"] + (0.0 if sign > 0 else ranges.behind_speed_delta[1])
    else:
        d0 = -v * (t_arr + p["offset"])

    def other(manoeuvre: str, accel: float) -> list[Track]:
        return [intersection_track(SOURCE[position], manoeuvre, d0, v, np.full_like(v, accel),
                                   ranges.event_time, road.approach, road.lane_width,
                                   OTHER_SIZE)]  # fmt: skip

    flat = np.zeros_like(ego.x)
    hits = obstructs(ego, other(manoeuvre, accel), flat) & ~obstructs(
        ego, other("straight", 0.0), flat
    )
    if hits.any():
        return Cell(c, position, 1, "obstructs", f"crosses the ego's path in {hits.sum()} probes")
    return Cell(c, position, 1, "non-obstructing", "its path never meets the ego's")


def expand(combination: Combination, ranges: Ranges | None = None) -> list[Cell]:
    """Every position x lane count of ``combination`` with its verdict and reason."""
    ranges = ranges or Ranges()
    if combination.geometry == Geometry.INTERSECTION:
        return [_intersection_cell(combination, pos, ranges) for pos in INTERSECTION_POSITIONS]
    positions = (Position.FRONT,) if combination.prefix == "C" else ADJACENT
    return [
        _motorway_cell(combination, pos, lanes, ranges)
        for lanes in LANE_COUNTS
        for pos in positions
    ]
