"""Where two actors touched and the likely reason, from the WorldState of the first contact,
so that a traffic run's collision count can be read: which actors, where, why.

SUMO moves each vehicle along its lane's centre line and orders the foes of a junction by link
timing (who may enter when), not by their outlines. Inside a junction a vehicle waiting to
turn, or turning slowly, therefore reaches a few centimetres into a crossing foe's path, and a
long vehicle's rectangle cuts the inside of a curve over the kerb. Such contacts are artefacts
of the junction model at this scale, not crashes; a report should say so rather than count
them as accidents.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.collision import Collision
from hiyari.traffic.world_state import WorldState

#: m: overlaps up to this (rectangles touching by centimetres) are called a model contact
SHALLOW_M = 0.1
#: rad: two vehicles whose headings differ more than this are on crossing paths
CROSSING_RAD = np.radians(20.0)
#: The short categories of ``ContactContext.reason``.
REASONS = ("junction model", "turning sweep over the kerb", "rear-end", "on a crossing",
           "other")  # fmt: skip


@dataclass(frozen=True)
class ContactContext:
    """One contact explained: the actors' class, lane and speed (m/s) at first contact,
    ``where`` (a junction, crossing, walking area or edge), ``reason`` (a short category) and
    ``why`` (one sentence)."""

    a_class: str
    b_class: str
    a_lane: str
    b_lane: str
    a_speed: float
    b_speed: float
    where: str
    reason: str  # one of REASONS
    why: str


def place(lane: str) -> str:
    """A lane id as a place: ':C_7_0' -> 'junction C', ':C_c0_0' -> 'crossing of junction C',
    ':C_w1_0' -> 'walking area of junction C', 's_in_0' -> 'edge s_in'."""
    if not lane:
        return "off the road network"
    edge = lane.rsplit("_", 1)[0]
    if not edge.startswith(":"):
        return f"edge {edge}"
    junction, _, part = edge[1:].rpartition("_")
    if part.startswith("c"):
        return f"crossing of junction {junction}"
    if part.startswith("w"):
        return f"walking area of junction {junction}"
    return f"junction {junction}"


def explain(contact: Collision, state: WorldState) -> ContactContext:
    """The context of ``contact`` in ``state`` (the step it was first seen in)."""
    if not (np.any(state.ids == contact.a) and np.any(state.ids == contact.b)):
        why = "reported by SUMO for an actor it removed in the same step"
        return ContactContext("", "", "", "", np.nan, np.nan, "unknown", "other", why)
    i, j = state.index(contact.a), state.index(contact.b)
    cls = [ActorClass(int(state.cls[k])) for k in (i, j)]
    lanes = [str(state.lane[k]) for k in (i, j)]
    places = [place(lane) for lane in lanes]
    where = places[0] if places[0] == places[1] else f"{places[0]} / {places[1]}"
    cm = f"{100 * contact.depth:.0f} cm"
    shallow = contact.depth <= SHALLOW_M
    if contact.kind == "vehicle-vehicle":
        turn = abs((state.heading[i] - state.heading[j] + np.pi) % (2 * np.pi) - np.pi)
        inside = all(p.startswith("junction ") for p in places) and places[0] == places[1]
        reason = "other"
        if inside and turn > CROSSING_RAD:
            reason = "junction model" if shallow else "other"
            why = (
                f"conflicting paths inside {places[0]} (headings {np.degrees(turn):.0f}° apart): "
                "SUMO orders "
                "junction foes by link timing, not by outline, so a vehicle waiting or turning "
                f"inside the junction reaches into its foe's path; the rectangles overlap {cm}"
                + (": a junction-model contact, not a crash" if shallow else "")
            )
        elif lanes[0] == lanes[1]:
            reason = "rear-end"
            why = f"one behind the other on lane {lanes[0]}; the rectangles overlap {cm}"
        else:
            why = f"on different lanes ({lanes[0]}, {lanes[1]}); the rectangles overlap {cm}"
    else:
        v, p = (i, j) if cls[1] == ActorClass.PEDESTRIAN else (j, i)
        v_place, p_place = place(str(state.lane[v])), place(str(state.lane[p]))
        vehicle = f"{state.length[v]:.0f} m {ActorClass(int(state.cls[v])).label}"
        reason = "other"
        if v_place.startswith("junction ") and not p_place.startswith("crossing"):
            reason = "turning sweep over the kerb"
            why = (
                f"a {vehicle} turning through {v_place}: moved along the lane's centre line, "
                f"its rectangle cuts the inside of the curve over the kerb, where the pedestrian "
                f"walks ({p_place}); overlap {cm}"
            )
        elif p_place.startswith("crossing"):
            reason = "on a crossing"
            why = f"the pedestrian on the crossing as the {vehicle} drove over it; overlap {cm}"
        else:
            why = f"the {vehicle} and the pedestrian on {where}; overlap {cm}"
    return ContactContext(
        cls[0].label, cls[1].label, lanes[0], lanes[1],
        round(float(state.speed[i]), 2), round(float(state.speed[j]), 2), where, reason, why,
    )  # fmt: skip


def reason_counts(contexts: list[ContactContext]) -> str:
    """'3 junction model, 1 turning sweep over the kerb': the contacts by reason."""
    n = {r: sum(c.reason == r for c in contexts) for r in REASONS}
    return ", ".join(f"{k} {r}" for r, k in n.items() if k) or "none"
