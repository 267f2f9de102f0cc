"""The lateral profile of OpenDRIVE roads (lane offset and lane width polynomials) as flat
arrays, and its compiled evaluation: the t of a lane's centre line and the lane's width at a
road s. This is the one definition of lane centre lines: ``Road.lane_t`` /
``Road.lane_centre_t`` evaluate it for one road, the scenario engine's motion kernel for the
roads its actors are on.

A record is a cubic a + b ds + c ds^2 + d ds^3 valid from its ``s0`` (lane offset: road s;
lane widths: s from the start of their lane section). Frames and units: road s and t in
metres, t to the left of the reference line; lane ids in OpenDRIVE numbering (negative =
right of the reference line).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from hiyari.jit import njit

if TYPE_CHECKING:
    from hiyari.net.road.opendrive_lanes import Poly3, Road


@dataclass(frozen=True)
class LaneProfile:
    """Lane offset and lane widths of ``roads`` (indexed 0..R-1 in the order given).

    ``rec_s0`` (N,) / ``rec_c`` (N, 4): every cubic record; road r's lane offset records are
    ``off_first[r]`` .. + ``off_count[r]``; its lane sections ``sec_first[r]`` .. +
    ``sec_count[r]`` (start s ``sec_s0``); lane ``id`` of section k has its width records at
    ``w_first[k, id + max_lane]`` .. + ``w_count[k, id + max_lane]`` (count -1: the section has
    no such lane)."""

    rec_s0: np.ndarray
    rec_c: np.ndarray
    off_first: np.ndarray
    off_count: np.ndarray
    sec_first: np.ndarray
    sec_count: np.ndarray
    sec_s0: np.ndarray
    w_first: np.ndarray
    w_count: np.ndarray
    max_lane: int

    def arrays(self) -> tuple:
        """The arrays in the order the compiled functions take them (``max_lane`` last)."""
        return (
            self.rec_s0, self.rec_c, self.off_first, self.off_count, self.sec_first,
            self.sec_count, self.sec_s0, self.w_first, self.w_count, self.max_lane,
        )  # fmt: skip


def lane_profile(roads: Sequence[Road]) -> LaneProfile:
    """The LaneProfile of ``roads``."""
    max_lane = max((abs(i) for r in roads for sec in r.sections for i in sec.lanes), default=0)
    records: list[Poly3] = []
    off_first, off_count, sec_first, sec_count, sec_s0 = [], [], [], [], []
    w_first, w_count = [], []
    for road in roads:
        off_first.append(len(records))
        off_count.append(len(road.lane_offset))
        records.extend(road.lane_offset)
        sec_first.append(len(sec_s0))
        sec_count.append(len(road.sections))
        for sec in road.sections:
            sec_s0.append(sec.s0)
            first, count = [0] * (2 * max_lane + 1), [-1] * (2 * max_lane + 1)
            for lane_id, spec in sec.lanes.items():
                if lane_id != 0:
                    first[lane_id + max_lane] = len(records)
                    count[lane_id + max_lane] = len(spec.widths)
                    records.extend(spec.widths)
            w_first.append(first)
            w_count.append(count)
    width = 2 * max_lane + 1
    return LaneProfile(
        np.array([r.s0 for r in records], dtype=float),
        np.array([(r.a, r.b, r.c, r.d) for r in records], dtype=float).reshape(-1, 4),
        np.array(off_first, dtype=np.int64),
        np.array(off_count, dtype=np.int64),
        np.array(sec_first, dtype=np.int64),
        np.array(sec_count, dtype=np.int64),
        np.array(sec_s0, dtype=float),
        np.array(w_first, dtype=np.int64).reshape(-1, width),
        np.array(w_count, dtype=np.int64).reshape(-1, width),
        max_lane,
    )


@njit(cache=True)
def cubic_at(rec_s0: np.ndarray, rec_c: np.ndarray, first: int, count: int, s: float) -> float:
    """Piecewise cubic records ``first`` .. + ``count`` (sorted by s0) at ``s``: the last
    record starting at or before ``s`` (the first before them all); 0 without records."""
    if count <= 0:
        return 0.0
    k = first
    for j in range(first + 1, first + count):
        if rec_s0[j] <= s:
            k = j
        else:
            break
    ds = s - rec_s0[k]
    return rec_c[k, 0] + ds * (rec_c[k, 1] + ds * (rec_c[k, 2] + ds * rec_c[k, 3]))


@njit(cache=True)
def section_of(sec_s0: np.ndarray, first: int, count: int, s: float) -> int:
    """Index (into the profile's sections) of the lane section of a road holding road ``s``."""
    k = first
    for j in range(first + 1, first + count):
        if sec_s0[j] <= s:
            k = j
        else:
            break
    return k


@njit(cache=True)
def lane_centre_at(
    rec_s0: np.ndarray,
    rec_c: np.ndarray,
    off_first: np.ndarray,
    off_count: np.ndarray,
    sec_first: np.ndarray,
    sec_count: np.ndarray,
    sec_s0: np.ndarray,
    w_first: np.ndarray,
    w_count: np.ndarray,
    max_lane: int,
    road: int,
    lane: int,
    s: float,
) -> tuple[float, float, int]:
    """(t of lane ``lane``'s centre line, its width, -1) at road ``s`` of road ``road``; (NaN,
    NaN, section index in the profile) when that lane section has no such lane."""
    k = section_of(sec_s0, sec_first[road], sec_count[road], s)
    slot = lane + max_lane
    if lane == 0 or slot < 0 or slot > 2 * max_lane or w_count[k, slot] < 0:
        return np.nan, np.nan, k
    side = 1.0 if lane > 0 else -1.0
    ds = s - sec_s0[k]
    inner = 0.0
    for j in range(1, abs(lane)):
        other = int(side) * j + max_lane
        if w_count[k, other] >= 0:  # a missing inner lane has no width
            inner += cubic_at(rec_s0, rec_c, w_first[k, other], w_count[k, other], ds)
    w = cubic_at(rec_s0, rec_c, w_first[k, slot], w_count[k, slot], ds)
    base = cubic_at(rec_s0, rec_c, off_first[road], off_count[road], s)
    return base + side * (inner + 0.5 * w), w, -1


@njit(cache=True)
def lane_centres(
    rec_s0: np.ndarray,
    rec_c: np.ndarray,
    off_first: np.ndarray,
    off_count: np.ndarray,
    sec_first: np.ndarray,
    sec_count: np.ndarray,
    sec_s0: np.ndarray,
    w_first: np.ndarray,
    w_count: np.ndarray,
    max_lane: int,
    road: int,
    lane: int,
    s: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, int]:
    """:func:`lane_centre_at` over the road s values ``s``: (t, width, -1), or the first
    lane section (lowest index) lacking the lane as the last item."""
    t, width = np.empty(len(s)), np.empty(len(s))
    missing = -1
    for i in range(len(s)):
        t[i], width[i], k = lane_centre_at(
            rec_s0, rec_c, off_first, off_count, sec_first, sec_count, sec_s0, w_first,
            w_count, max_lane, road, lane, s[i],
        )  # fmt: skip
        if k >= 0 and (missing < 0 or k < missing):
            missing = k
    return t, width, missing
