"""Blind-spot combinations: occluder position x hidden position x hidden-vehicle motion.

Position grid (jama-C 7.1, inferred from the text: the figure is lost): lanes L2, L1, ego, R1,
R2 (offsets +2..-2, + left) x slots 2nd ahead, ahead, beside, behind, 2nd behind (+2..-2):

    slot   L2  L1  ego  R1  R2
    +2     20  13   9   11  15
    +1     21   6   1    3  16
     0     22   7  ego   4  17
    -1     23   8   2    5  18
    -2     24  14  10   12  19

Occluders (a truck) and the hidden positions left after the text's dominance reduction:
1 (ahead) -> 3, 6, 9, 11, 13; 4 (beside right) -> 1, 2, 3, 5; 3 (diagonal ahead right) -> 1, 9,
11, 15, 16; by the left-right symmetry the text applies, 7 (beside left) -> 1, 2, 6, 8 and
6 (diagonal ahead left) -> 1, 9, 13, 20, 21. Motions: cut-in, cut-out, accelerate,
decelerate, sync.

Realisable (can obstruct the ego), from the text's rules plus the toolkit's reading where the
figure is lost: sync never (text); deceleration only ahead of the ego (text: none from rear
positions; beside: it falls behind); acceleration only from beside or behind (ahead it
drives away); cut-in only from another lane; cut-out only from the ego's lane, not beside it.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

GRID: dict[int, tuple[int, int]] = {
    9: (0, 2), 1: (0, 1), 2: (0, -1), 10: (0, -2),
    13: (1, 2), 6: (1, 1), 7: (1, 0), 8: (1, -1), 14: (1, -2),
    20: (2, 2), 21: (2, 1), 22: (2, 0), 23: (2, -1), 24: (2, -2),
    11: (-1, 2), 3: (-1, 1), 4: (-1, 0), 5: (-1, -1), 12: (-1, -2),
    15: (-2, 2), 16: (-2, 1), 17: (-2, 0), 18: (-2, -1), 19: (-2, -2),
}  # fmt: skip
"""Position number -> (lane offset, + left; longitudinal slot, + ahead)."""


class Geometry(StrEnum):
    """Road geometry of a blind-spot case."""

    STRAIGHT = "straight"
    LEFT = "left curve"
    RIGHT = "right curve"


# jama-C 7.1: hidden positions per occluder and geometry, as the text lists them
BLIND_BY_GEOMETRY: dict[int, dict[Geometry, frozenset[int]]] = {
    1: {
        Geometry.STRAIGHT: frozenset({9}),
        Geometry.RIGHT: frozenset({6, 9, 13, 20, 21}),
        Geometry.LEFT: frozenset({3, 9, 11, 15, 16}),
    },
    4: {
        Geometry.STRAIGHT: frozenset({3, 5, 16, 17, 18}),
        Geometry.RIGHT: frozenset({1, 2, 3, 5, 6, 8, 16, 17, 18, 21, 23}),
        Geometry.LEFT: frozenset({16, 17, 18}),
    },
    3: {
        Geometry.STRAIGHT: frozenset({11, 15, 16}),
        Geometry.RIGHT: frozenset({1, 6, 9, 11, 13, 15, 16, 20, 21}),
        Geometry.LEFT: frozenset({15, 16}),
    },
}
REDUCED: dict[int, tuple[int, ...]] = {1: (3, 6, 9, 11, 13), 4: (1, 2, 3, 5), 3: (1, 9, 11, 15, 16)}
"""jama-C 7.1: the final hidden positions per worked occluder after the dominance reduction."""


class Motion(StrEnum):
    """What the hidden vehicle does."""

    CUT_IN = "cut-in"
    CUT_OUT = "cut-out"
    ACCELERATE = "accelerate"
    DECELERATE = "decelerate"
    SYNC = "sync"


def mirror(pos: int) -> int:
    """The position mirrored left <-> right."""
    lane, slot = GRID[pos]
    return next(p for p, ls in GRID.items() if ls == (-lane, slot))


def _mirror_geometry(g: Geometry) -> Geometry:
    return {Geometry.LEFT: Geometry.RIGHT, Geometry.RIGHT: Geometry.LEFT}.get(g, g)


def occluder_cases() -> dict[int, tuple[int, ...]]:
    """Occluder -> reduced hidden positions: the three worked cases plus their mirrors."""
    out = dict(REDUCED)
    for occ in (4, 3):
        out[mirror(occ)] = tuple(sorted(mirror(p) for p in REDUCED[occ]))
    return out


def geometry_for(occluder: int, hidden: int) -> Geometry:
    """A geometry in which the text has ``occluder`` hide ``hidden`` (straight first)."""
    base, flip = (occluder, False) if occluder in BLIND_BY_GEOMETRY else (mirror(occluder), True)
    target = mirror(hidden) if flip else hidden
    for g in (Geometry.STRAIGHT, Geometry.RIGHT, Geometry.LEFT):
        if target in BLIND_BY_GEOMETRY[base][g]:
            return _mirror_geometry(g) if flip else g
    raise ValueError(f"position {hidden} is not hidden by occluder {occluder} in the text")


def realisable(hidden: int, motion: Motion) -> tuple[bool, str]:
    """Whether a hidden vehicle at ``hidden`` doing ``motion`` can obstruct the ego, and why."""
    lane, slot = GRID[hidden]
    match motion:
        case Motion.SYNC:
            return False, "sync with the ego is not dangerous (text)"
        case Motion.DECELERATE:
            return slot > 0, "ahead of the ego" if slot > 0 else "not ahead: falls behind (text)"
        case Motion.ACCELERATE:
            return slot <= 0, "closes in from beside / behind" if slot <= 0 else "drives away"
        case Motion.CUT_IN:
            return lane != 0, "changes toward the ego lane" if lane != 0 else "already in it"
        case Motion.CUT_OUT:
            ok = lane == 0 and slot != 0
            return (
                ok,
                "leaves the ego lane in front of / behind it" if ok else "not in the ego lane",
            )
    raise ValueError(motion)


@dataclass(frozen=True)
class Combination:
    """One occluder x hidden vehicle x motion."""

    occluder: int
    hidden: int
    motion: Motion
    geometry: Geometry
    realisable: bool
    reason: str

    @property
    def name(self) -> str:
        """Short id, e.g. 'occ1-hid3-cut-in-left'."""
        return (
            f"occ{self.occluder}-hid{self.hidden}-{self.motion.value}-{self.geometry.name.lower()}"
        )


def combinations() -> list[Combination]:
    """Every occluder case x reduced hidden position x motion, with realisability."""
    out = []
    for occ, hidden in occluder_cases().items():
        for h in hidden:
            for m in Motion:
                ok, why = realisable(h, m)
                out.append(Combination(occ, h, m, geometry_for(occ, h), ok, why))
    return out
