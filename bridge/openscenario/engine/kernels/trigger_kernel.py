"""One compiled pass per step over every condition of the storyboard: measure the entity rows
of the triggers being evaluated (and the duration rows, always tracked), compare, reduce rows
to conditions ("any" / "all"), apply edges and delays, and reduce conditions to triggers (OR
of AND groups).

The tables are built by :class:`conditions.ConditionBank`. Columns of ``cond`` (one row per
condition): kind (``STATIC``, ``TIME``, ``STATE``, ``ENTITY``), trigger, element, state code,
rule ("all" 0 / "any" 1 for entity conditions, the rule code for time conditions), edge
(0 none, 1 rising, 2 falling, 3 both) and delay in steps. Columns of ``rows`` (one row per
entity-condition row): owner condition, entity a, entity b (-1 none), rule, kind, freespace,
distance type, frame (measures.ENTITY_FRAME, ROAD_FRAME, WORLD_FRAME), always measured.
"""

from __future__ import annotations

import math

import numpy as np

from hiyari.bridge.openscenario.engine.kernels.measures import (
    ACCEL,
    COLLISION,
    DIR_LAT,
    DIR_NONE,
    DISTANCE,
    E_ACC,
    E_H,
    E_V,
    END_OF_ROAD,
    REL_SPEED,
    ROAD_FRAME,
    SPEED,
    STANDSTILL,
    TRAVELED,
    TTC,
    TTC_POINT,
    duration_measure,
    entity_scalars,
    holds,
    in_road_of,
    lateral_accel_measure,
    pack_entities,
    pair_measure,
    point_measure,
    single_measure,
    total_accel_measure,
    traveled_measure,
    ttc_above,
)
from hiyari.bridge.openscenario.engine.kernels.snapshot import gather_entities
from hiyari.bridge.openscenario.engine.kernels.tables import (
    ActorArrays,
    ElementArrays,
    EntityFields,
    GatherArrays,
    TriggerArrays,
    WorldArrays,
)
from hiyari.jit import njit

#: Condition kinds (column 0 of the condition table).
STATIC, TIME, STATE, ENTITY = 0, 1, 2, 3
#: Columns of the condition table.
C_KIND, C_TRIGGER, C_ELEMENT, C_CODE, C_RULE, C_EDGE, C_DELAY = range(7)
#: Columns of the entity-row table.
R_OWNER, R_A, R_B, R_RULE, R_KIND, R_FS, R_DTYPE, R_ROAD, R_ALWAYS = range(9)
#: Element state codes below this are states; the others transitions.
FIRST_TRANSITION = 3


@njit(cache=True)
def _row_holds(
    kind: int,
    rule: int,
    value: float,
    now: float,
    fs: bool,
    dtype: int,
    frame: int,
    present_a: bool,
    present_b: bool,
    ea: tuple,
    eb: tuple,
    on_net_a: bool,
    since: float,
    last: float,
    point: tuple,
) -> tuple[bool, float, float]:
    """Whether an entity row (not a collision row) of ``kind`` holds against ``value`` now,
    and its tracked state to keep (``since``, ``last``: a duration state's start time, see
    measures.duration_measure, or the distance travelled and the time it was measured at,
    see measures.traveled_measure), given its entities' presence and fields (``ea``, ``eb``:
    measures.entity_scalars; ``eb`` is any entity's when the row has none) and its point
    (world x, y and road s, t: measures.point_measure). A lateral or total acceleration row
    keeps the heading and time of its previous evaluation (measures.lateral_accel_measure; it is
    measured every step). An absent entity measures NaN,
    which no rule holds for. Scalars only: a compiled helper called with array arguments
    pays a reference count per array and row."""
    if STANDSTILL <= kind <= END_OF_ROAD:
        m, since = duration_measure(kind, now, present_a, ea[E_V], on_net_a, since)
        return holds(m, value, rule), since, last
    if kind == TRAVELED:
        m, since, last = traveled_measure(now, present_a, ea[E_V], since, last)
        return holds(m, value, rule), since, last
    if kind == ACCEL and (dtype == DIR_LAT or dtype == DIR_NONE):
        m, since, last = lateral_accel_measure(now, present_a, ea[E_H], ea[E_V], since, last)
        if dtype == DIR_NONE:
            m = total_accel_measure(ea[E_ACC], m)
        return holds(m, value, rule), since, last
    if not present_a or ((kind < SPEED or kind == REL_SPEED) and not present_b):
        return False, since, last
    if kind < SPEED:
        if (
            kind == TTC
            and fs
            and dtype == 0
            and frame != ROAD_FRAME
            and value < math.inf
            and ttc_above(value, ea, eb)
        ):  # certainly above the value: every rule decides as for an infinite TTC
            return holds(math.inf, value, rule), since, last
        return holds(pair_measure(kind, fs, dtype, frame, ea, eb), value, rule), since, last
    if kind <= REL_SPEED:
        return holds(single_measure(kind, dtype, ea, eb), value, rule), since, last
    if DISTANCE <= kind <= TTC_POINT:
        return holds(point_measure(kind, fs, dtype, frame, ea, point), value, rule), since, last
    return False, since, last


@njit(cache=True)
def _condition_values(
    now: float, trig: TriggerArrays, ent: EntityFields, el: ElementArrays, raw: np.ndarray
) -> None:
    """Into ``raw`` (C,): whether each condition holds now, before edges and delays
    (conditions of inactive triggers: False; their duration rows are still tracked).
    ``trig.work`` and ``trig.counts``: work arrays (the entities' fields packed, see
    measures.pack_entities; rows holding and rows evaluated per condition)."""
    work, cond, rows, since, points = trig.work, trig.cond, trig.rows, trig.since, trig.points
    active, present = el.active, ent.present
    pack_entities(ent, work)
    n = len(cond)
    hits, count = trig.counts[0], trig.counts[1]
    hits[:] = 0
    count[:] = 0
    for r in range(len(rows)):
        owner = rows[r, R_OWNER]
        on = active[cond[owner, C_TRIGGER]]
        if not (on or rows[r, R_ALWAYS]):
            continue
        if rows[r, R_KIND] == COLLISION:
            a, b = rows[r, R_A], rows[r, R_B]
            res = ent.contact[a, b] if b >= 0 else ent.contact_any[a]
        else:
            a, b = rows[r, R_A], rows[r, R_B]
            ea, eb = entity_scalars(a, work), entity_scalars(max(b, 0), work)
            if rows[r, R_ROAD] == ROAD_FRAME and b >= 0:
                eb = in_road_of(ea, eb, trig.links)  # along the links when on another road
            res, since[r, 0], since[r, 1] = _row_holds(
                rows[r, R_KIND], rows[r, R_RULE], trig.row_value[r], now, rows[r, R_FS] != 0,
                rows[r, R_DTYPE], rows[r, R_ROAD], present[a], b >= 0 and present[b],
                ea, eb, ent.on_net[a],
                since[r, 0], since[r, 1],
                (points[r, 0], points[r, 1], points[r, 2], points[r, 3]),
            )  # fmt: skip
        if on:
            count[owner] += 1
            hits[owner] += res
    for c in range(n):
        raw[c] = False
        kind = cond[c, C_KIND]
        if kind == STATIC:
            raw[c] = trig.static[c]
        elif kind == TIME:
            raw[c] = holds(now, trig.time_value[c], cond[c, C_RULE])
        elif kind == STATE:
            e, code = cond[c, C_ELEMENT], cond[c, C_CODE]
            raw[c] = (el.states[e] if code < FIRST_TRANSITION else el.transitions[e]) == code
        elif count[c] > 0:
            raw[c] = hits[c] > 0 if cond[c, C_RULE] == 1 else hits[c] == count[c]


@njit(cache=True)
def _edges_and_delays(
    raw: np.ndarray,
    active: np.ndarray,
    cond: np.ndarray,
    prev: np.ndarray,
    history: np.ndarray,
    step_no: int,
    out: np.ndarray,
) -> None:
    """Into ``out`` (C,): each condition's value after its edge and delay. ``prev`` (value at
    the previous evaluation, -1: not evaluated since its trigger became active) and the ring
    buffer ``history`` (C, H) of edged values are updated for step ``step_no``."""
    n, size = len(cond), history.shape[1]
    k = step_no % size
    for c in range(n):
        on = active[cond[c, C_TRIGGER]]
        edge, value = cond[c, C_EDGE], raw[c]
        if edge == 0:
            edged = value
        else:
            rising = prev[c] == 0 and value and (edge == 1 or edge == 3)
            falling = prev[c] == 1 and not value and (edge == 2 or edge == 3)
            edged = rising or falling
        edged = edged and on
        prev[c] = (1 if value else 0) if on else -1
        if size == 1:
            out[c] = edged
            continue
        history[c, k] = edged
        delay = cond[c, C_DELAY]
        out[c] = history[c, (step_no - delay) % size] and delay <= step_no


@njit(cache=True)
def evaluate_triggers(
    now: float, step_no: int, trig: TriggerArrays, ent: EntityFields, el: ElementArrays
) -> int:
    """Into ``trig.fired`` (T,), returning how many: the fired triggers at scenario time
    ``now`` (s), step ``step_no`` since the bank was built, given which triggers are active
    (``el``) and what the entities are (``ent``)."""
    trig, ent, el = TriggerArrays(*trig), EntityFields(*ent), ElementArrays(*el)
    active, trigger_group, group_start, fired = (
        el.active, trig.trigger_group, trig.group_start, trig.fired
    )  # fmt: skip
    raw, value = trig.flags[0], trig.flags[1]
    _condition_values(now, trig, ent, el, raw)
    _edges_and_delays(raw, active, trig.cond, trig.prev, trig.history, step_no, value)
    n_trig, n_fired = len(trigger_group) - 1, 0
    for t in range(n_trig):
        fired[t] = False
        if not active[t]:
            continue
        for g in range(trigger_group[t], trigger_group[t + 1]):
            all_hold = True
            for c in range(group_start[g], group_start[g + 1]):
                all_hold = all_hold and value[c]
            if all_hold:
                fired[t] = True
                n_fired += 1
                break
    return n_fired


@njit(cache=True)
def gather_and_evaluate(
    now: float,
    step_no: int,
    world: WorldArrays,
    gather: GatherArrays,
    actors: ActorArrays,
    trig: TriggerArrays,
    ent: EntityFields,
    el: ElementArrays,
) -> int:
    """:func:`snapshot.gather_entities` into ``ent`` and then :func:`evaluate_triggers` on
    what it gathered, in one call (a step's snapshot and triggers when no entity's road
    coordinates are located in Python)."""
    gather_entities(world, gather, actors, ent)
    return evaluate_triggers(now, step_no, trig, ent, el)


@njit(cache=True)
def road_entities(
    active: np.ndarray,
    row_trigger: np.ndarray,
    road: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    n_entities: int,
) -> np.ndarray:
    """(E,) the entities (``a`` and ``b``, -1: none) of the entity rows in road coordinates
    (``road``: their frame is ROAD_FRAME) whose trigger (``row_trigger``) is ``active``."""
    need = np.zeros(n_entities, dtype=np.bool_)
    for r in range(len(row_trigger)):
        if road[r] == ROAD_FRAME and active[row_trigger[r]]:
            need[a[r]] = True
            if b[r] >= 0:
                need[b[r]] = True
    return need
