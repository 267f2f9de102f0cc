"""Contact between actors from their oriented ground rectangles (separating-axis test) and
their heights: two actors touch only where their rectangles overlap and their height ranges
[z, z + height] overlap too (a car on a bridge passes over the car below it).

SUMO reports only some contacts (vehicles on the same or crossing lanes); geometry catches the
rest, such as a pedestrian stepping into a car's path off any crossing. Both are merged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from hiyari.kinematics import overlap_depth
from hiyari.traffic.actor_class import CLASS_SIZE, ActorClass
from hiyari.traffic.world_state import WorldState

#: Default height per ActorClass value, m (the one size table, CLASS_SIZE).
_CLASS_HEIGHT = np.array([CLASS_SIZE[c].height for c in sorted(ActorClass)])


@dataclass(frozen=True)
class Collision:
    """Two actors in contact at ``time`` (s). ``a`` < ``b`` lexicographically.

    ``depth`` is the smallest overlap along any separating axis (m); 0 when only SUMO saw it.
    """

    time: float
    a: str
    b: str
    kind: str  # "vehicle-vehicle" or "vehicle-pedestrian"
    depth: float
    reported_by_sumo: bool


class CollisionDetector:
    """Finds vehicle–vehicle and vehicle–pedestrian contacts in a WorldState."""

    def __init__(self, tolerance: float = 0.0, ignore_walkingarea_contacts: bool = True) -> None:
        """``tolerance`` (m): overlaps at or below it are not contacts.

        ``ignore_walkingarea_contacts``: SUMO's corner walking areas overlap the swept path of
        turning vehicles by construction, so a pedestrian standing there is clipped by every
        right-turner (overlaps up to ~0.3 m seen); such geometric contacts are not counted
        unless SUMO reports them too.
        """
        self.tolerance = tolerance
        self.ignore_walkingarea_contacts = ignore_walkingarea_contacts

    def detect(
        self, state: WorldState, sumo_pairs: list[tuple[str, str]] | None = None
    ) -> list[Collision]:
        """Contacts at this step, geometric and SUMO-reported, each pair once."""
        found: dict[tuple[str, str], Collision] = {}
        ped = state.is_pedestrian
        if len(state) > 1:
            radius = 0.5 * np.hypot(state.length, state.width)
            tree = cKDTree(state.xyz[:, :2])
            pairs = tree.query_pairs(2.0 * float(radius.max()), output_type="ndarray")
            if len(pairs):
                i, j = pairs[:, 0], pairs[:, 1]
                keep = ~(ped[i] & ped[j])
                centre_gap = np.linalg.norm(state.xyz[i, :2] - state.xyz[j, :2], axis=1)
                keep &= centre_gap <= radius[i] + radius[j]
                keep &= _levels_overlap(state, i, j)
                i, j = i[keep], j[keep]
                if self.ignore_walkingarea_contacts and len(i):
                    lane = state.lane
                    on_wa = np.array(
                        [
                            _on_walkingarea(lane[a]) or _on_walkingarea(lane[b])
                            for a, b in zip(i, j, strict=True)
                        ],
                        dtype=bool,
                    )
                    on_wa &= ped[i] | ped[j]
                    i, j = i[~on_wa], j[~on_wa]
                rows, inverse = np.unique(np.concatenate([i, j]), return_inverse=True)
                corners = state.select(rows).corners()
                depth = overlap_depth(corners[inverse[: len(i)]], corners[inverse[len(i) :]])
                hit = depth > self.tolerance
                for a, b, d in zip(i[hit], j[hit], depth[hit], strict=True):
                    key = tuple(sorted((state.ids[a], state.ids[b])))
                    kind = "vehicle-pedestrian" if ped[a] or ped[b] else "vehicle-vehicle"
                    found[key] = Collision(state.time, key[0], key[1], kind, float(d), False)
        ped_ids = set(state.ids[ped].tolist()) if sumo_pairs else set()
        for a, b in sumo_pairs or ():
            key = tuple(sorted((a, b)))
            if key in found:
                c = found[key]
                found[key] = Collision(c.time, c.a, c.b, c.kind, c.depth, True)
            else:
                kind = "vehicle-pedestrian" if a in ped_ids or b in ped_ids else "vehicle-vehicle"
                found[key] = Collision(state.time, key[0], key[1], kind, 0.0, True)
        return [found[k] for k in sorted(found)]


def _levels_overlap(state: WorldState, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """(P,) bool: the height ranges [z, z + height] of actors i and j overlap (z from SUMO's
    3-D position, m; an actor whose state carries no height gets its class's from
    CLASS_SIZE)."""
    height = np.where(state.height > 0, state.height, _CLASS_HEIGHT[state.cls.astype(np.intp)])
    z = state.xyz[:, 2]
    return (z[i] < z[j] + height[j]) & (z[j] < z[i] + height[i])


def _on_walkingarea(lane: str) -> bool:
    """SUMO walking areas are internal lanes named ':<junction>_w<k>_0'."""
    return lane.startswith(":") and "_w" in lane
