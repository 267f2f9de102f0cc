"""The JAMA traffic-disturbance taxonomy (§4.1.1): road geometry x ego motion x surrounding
vehicle position x motion, and the representative combinations (Fig. 47 / 48).

Motorway: 3 geometries x 2 ego motions x 4 surrounding motions = the 24 combinations of
Fig. 48, numbered so that No. 5-8 are (main line, lane change, *) as the text states (the rest
of the order is ours). General roads add the intersection, ego turns, crossing and oncoming
positions and the turning / U-turning / swerving motions (§4.1.1.1-3); the text does not give
Fig. 47's 58-case mask, so the general catalogue is this product filtered by the same
geometric obstruction test as the motorway one.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum


class Geometry(StrEnum):
    """Road geometry (§4.1.1.1); motorways use only main line, merge and branch."""

    MAIN = "main line"
    MERGE = "merge"
    BRANCH = "branch"
    INTERSECTION = "intersection"


class EgoMotion(StrEnum):
    """Ego motion (§4.1.1.2): lane keep, lane change (from an adjacent or a merge lane), turn."""

    LANE_KEEP = "lane keep"
    LANE_CHANGE = "lane change"
    TURN_LEFT = "turn left"
    TURN_RIGHT = "turn right"


class Position(StrEnum):
    """Surrounding-vehicle position relative to the ego at the start (§4.1.1.3): the six
    around the ego (no "directly beside": front / rear initial gaps cover it), "+1" ahead of
    the lead, crossing from the left / right, oncoming."""

    FRONT = "front"
    REAR = "rear"
    LEFT_FRONT = "left front"
    LEFT_REAR = "left rear"
    RIGHT_FRONT = "right front"
    RIGHT_REAR = "right rear"
    PLUS_ONE = "+1"
    CROSSING_LEFT = "crossing left"
    CROSSING_RIGHT = "crossing right"
    ONCOMING = "oncoming"


#: The positions that share the ego's carriageway.
ADJACENT = (
    Position.FRONT,
    Position.REAR,
    Position.LEFT_FRONT,
    Position.LEFT_REAR,
    Position.RIGHT_FRONT,
    Position.RIGHT_REAR,
    Position.PLUS_ONE,
)
INTERSECTION_POSITIONS = (
    Position.FRONT,
    Position.REAR,
    Position.CROSSING_LEFT,
    Position.CROSSING_RIGHT,
    Position.ONCOMING,
)


class Motion(StrEnum):
    """Surrounding-vehicle motion (§4.1.1.3, three groups)."""

    ACCELERATE = "accelerate"
    DECELERATE = "decelerate"
    CUT_IN = "cut-in"
    CUT_OUT = "cut-out"
    SWERVE = "swerve"
    TURN_LEFT = "turn left"
    TURN_RIGHT = "turn right"
    U_TURN = "U-turn"


GROUP = {
    Motion.ACCELERATE: "straight",
    Motion.DECELERATE: "straight",
    Motion.CUT_IN: "lane change",
    Motion.CUT_OUT: "lane change",
    Motion.SWERVE: "lane change",
    Motion.TURN_LEFT: "turn",
    Motion.TURN_RIGHT: "turn",
    Motion.U_TURN: "turn",
}


@dataclass(frozen=True)
class Combination:
    """One representative scenario (a row of Fig. 47 / 48)."""

    no: int
    geometry: Geometry
    ego: EgoMotion
    motion: Motion
    prefix: str = "M"  # M: motorway catalogue, G: general-road catalogue, C: §4.1.3 chains

    @property
    def key(self) -> str:
        """Short stable id, e.g. ``M05``."""
        return f"{self.prefix}{self.no:02d}"

    @property
    def title(self) -> str:
        return f"{self.geometry} / ego {self.ego} / {GROUP[self.motion]}: {self.motion}"


MOTORWAY_GEOMETRIES = (Geometry.MAIN, Geometry.MERGE, Geometry.BRANCH)
MOTORWAY_EGO = (EgoMotion.LANE_KEEP, EgoMotion.LANE_CHANGE)
MOTORWAY_MOTIONS = (Motion.ACCELERATE, Motion.DECELERATE, Motion.CUT_IN, Motion.CUT_OUT)
INTERSECTION_EGO = (EgoMotion.LANE_KEEP, EgoMotion.TURN_LEFT, EgoMotion.TURN_RIGHT)
INTERSECTION_MOTIONS = (
    Motion.ACCELERATE,
    Motion.DECELERATE,
    Motion.TURN_LEFT,
    Motion.TURN_RIGHT,
    Motion.U_TURN,
)


def motorway_combinations() -> list[Combination]:
    """The 24 motorway combinations (Fig. 48), No. 1-24."""
    rows = [(g, e, m) for g in MOTORWAY_GEOMETRIES for e in MOTORWAY_EGO for m in MOTORWAY_MOTIONS]
    return [Combination(i + 1, g, e, m, "M") for i, (g, e, m) in enumerate(rows)]


def general_combinations() -> list[Combination]:
    """The general-road extension as far as the text defines it: the motorway geometries
    with swerving added, and the intersection with ego turns and turning / U-turning actors."""
    rows = [
        (g, e, m)
        for g in MOTORWAY_GEOMETRIES
        for e in MOTORWAY_EGO
        for m in (*MOTORWAY_MOTIONS, Motion.SWERVE)
    ]
    rows += [(Geometry.INTERSECTION, e, m) for e in INTERSECTION_EGO for m in INTERSECTION_MOTIONS]
    return [Combination(i + 1, g, e, m, "G") for i, (g, e, m) in enumerate(rows)]


def chain_combinations() -> list[Combination]:
    """§4.1.3 chains: on each motorway geometry, the ego keeping its lane behind a lead that
    cuts out in front of a slower (not stopped) "+1" vehicle."""
    return [
        Combination(i + 1, g, EgoMotion.LANE_KEEP, Motion.CUT_OUT, "C")
        for i, g in enumerate(MOTORWAY_GEOMETRIES)
    ]
