"""All trigger conditions of a storyboard, compiled into arrays and evaluated together.

Every condition gets an index; entity conditions become one row per (condition, triggering
entity) pair in one table (see ``measures``). A step evaluates only the rows of triggers being
evaluated now (durations are always tracked), each group of kinds in one vectorised pass, then
compares every row with one operation and reduces rows to conditions ("any" / "all") with two
``bincount``. Edges and delays are tracked per condition while its trigger is active (the first
evaluation after activation has no edge). Triggers (OR of AND groups) are reduced with
``reduceat`` over the condition order.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from hiyari.bridge.scenario.engine import measures as M
from hiyari.bridge.scenario.engine.measures import EntityRows, Snapshot, compare
from hiyari.bridge.scenario.engine.positions import Pose
from hiyari.bridge.scenario.model.conditions import (
    AccelerationCondition,
    CollisionCondition,
    Condition,
    CoordinateSystem,
    DistanceCondition,
    DistanceType,
    Edge,
    EndOfRoadCondition,
    EntityCondition,
    ParameterCondition,
    ReachPositionCondition,
    RelativeDistanceCondition,
    RelativeSpeedCondition,
    Rule,
    SimulationTimeCondition,
    SpeedCondition,
    StandStillCondition,
    StoryboardElementStateCondition,
    TimeHeadwayCondition,
    TimeToCollisionCondition,
    Trigger,
)
from hiyari.errors import HiyariError

_RULES = list(Rule)
_EDGES = {Edge.NONE: 0, Edge.RISING: 1, Edge.FALLING: 2, Edge.RISING_OR_FALLING: 3}
_DTYPE = {DistanceType.EUCLIDEAN: 0, DistanceType.LONGITUDINAL: 1, DistanceType.LATERAL: 2}

__all__ = ["ConditionBank", "Snapshot", "compare"]


class ConditionBank:
    """Every condition of the storyboard's triggers, evaluated in batches."""

    def __init__(
        self,
        triggers: list[Trigger],
        entity_index: dict[str, int],
        element_index: Callable[[str, str, str], int],
        parameters: dict[str, object],
        resolve: Callable[[object], Pose],
        dt: float,
    ) -> None:
        self.entity_index = entity_index
        self.resolve = resolve
        self.conditions: list[Condition] = []
        cond_trigger: list[int] = []
        group_starts, trigger_groups = [], []
        for ti, trig in enumerate(triggers):
            trigger_groups.append(len(group_starts))
            for group in trig:
                group_starts.append(len(self.conditions))
                for c in group:
                    self.conditions.append(c)
                    cond_trigger.append(ti)
        n = len(self.conditions)
        self.n_triggers = len(triggers)
        self.empty = np.array([len(t) == 0 for t in triggers], dtype=bool)
        self.has_conditions = np.flatnonzero(~self.empty)
        self.group_starts = np.array(group_starts, dtype=np.intp)
        self.trigger_groups = np.array(trigger_groups, dtype=np.intp)
        self.cond_trigger = np.array(cond_trigger, dtype=np.intp)
        edge = np.array([_EDGES[c.edge] for c in self.conditions], dtype=np.int8)
        self.edge_none = edge == 0
        self.edge_rise = (edge == 1) | (edge == 3)
        self.edge_fall = (edge == 2) | (edge == 3)
        self.prev = np.full(n, -1, dtype=np.int8)  # -1: not evaluated since activation
        self._delays(dt)
        self._compile(element_index, parameters)

    # ------------------------------------------------------------------ compile
    def _delays(self, dt: float) -> None:
        d = np.array([c.delay for c in self.conditions])
        self.delay_steps = np.rint(d / dt).astype(np.int64) if len(d) else np.zeros(0, np.int64)
        size = int(self.delay_steps.max()) + 1 if len(d) else 1
        self.history = np.zeros((len(d), size), dtype=bool)
        self.cond_ix = np.arange(len(d))
        self.step_no = 0

    def _compile(self, element_index: Callable[[str, str, str], int], parameters: dict) -> None:
        time_ix, time_v, time_r = [], [], []
        state_ix, state_el = [], []
        self.static = np.zeros(len(self.conditions), dtype=bool)
        rows: list[tuple] = []
        for i, c in enumerate(self.conditions):
            b = c.body
            if isinstance(b, SimulationTimeCondition):
                time_ix.append(i), time_v.append(b.value), time_r.append(_RULES.index(b.rule))
            elif isinstance(b, StoryboardElementStateCondition):
                state_ix.append(i)
                state_el.append(element_index(b.element_type, b.element, c.source))
                self._check_state(b.state, c.source)
            elif isinstance(b, ParameterCondition):
                self.static[i] = _param_holds(parameters, b, c.source)
            elif isinstance(b, EntityCondition):
                rows += self._entity_rows(i, c, b)
            else:
                raise HiyariError(f"{c.source}: condition {type(b).__name__} is not supported")
        self.time_ix = np.array(time_ix, dtype=np.intp)
        self.time_v, self.time_r = np.array(time_v), np.array(time_r, dtype=np.int8)
        self.state_ix = np.array(state_ix, dtype=np.intp)
        self.state_el = np.array(state_el, dtype=np.intp)
        self.state_code = np.array(
            [_STATE_CODES[self.conditions[i].body.state] for i in state_ix], dtype=np.int8
        )
        self.state_is_state = self.state_code < 3
        self.rows = _table(rows)
        self.needs_road = bool(self.rows.road.any())
        self.row_trigger = self.cond_trigger[self.rows.owner]
        self.row_always = np.isin(self.rows.kind, M.DURATION_KINDS)  # durations: always tracked
        self.since = np.full(len(self.rows), np.nan)
        self.fixed: dict[int, tuple[float, float]] = {}
        self.groups = [
            (ix, kinds)
            for kinds in (M.PAIR_KINDS, M.SINGLE_KINDS, M.DURATION_KINDS, M.POINT_KINDS)
            if len(ix := np.flatnonzero(np.isin(self.rows.kind, kinds)))
        ]
        self.collision_rows = np.flatnonzero(self.rows.kind == M.COLLISION)
        self.rule_any = np.array(
            [
                not (isinstance(c.body, EntityCondition) and c.body.rule == "all")
                for c in self.conditions
            ],
            dtype=bool,
        )

    @staticmethod
    def _check_state(state: str, where: str) -> None:
        if state not in _STATE_CODES:
            raise HiyariError(f"{where}: unknown storyboard element state {state!r}")

    def _entity(self, name: str, where: str) -> int:
        try:
            return self.entity_index[name]
        except KeyError:
            raise HiyariError(f"{where}: no entity {name!r} in the scenario") from None

    def _entity_rows(self, i: int, c: Condition, ec: EntityCondition) -> list[tuple]:
        b = ec.body
        kind, other, value, rule = _classify(b)
        ref = self._entity(other, c.source) if isinstance(other, str) else -1
        rule_code = _RULES.index(rule) if rule is not None else 0
        return [
            (i, self._entity(name, c.source), ref, value, rule_code, kind, b)
            for name in ec.triggering
        ]

    def road_entities(self, active: np.ndarray) -> np.ndarray:
        """(E,) entities whose road coordinates the ``active`` triggers' rows read."""
        need = np.zeros(len(self.entity_index), dtype=bool)
        on = self.rows.road & active[self.row_trigger]
        need[self.rows.a[on]] = True
        b = self.rows.b[on]
        need[b[b >= 0]] = True
        return need

    # ------------------------------------------------------------------ evaluate
    def evaluate(
        self, snap: Snapshot, active: np.ndarray, states: np.ndarray, transitions: np.ndarray
    ) -> np.ndarray:
        """Fired triggers (bool per trigger) given which triggers are ``active``, element
        ``states`` (codes) and the ``transitions`` (codes) each element went through at the
        last update."""
        raw = self.static.copy()
        if len(self.time_ix):
            raw[self.time_ix] = compare(
                np.full(len(self.time_ix), snap.time), self.time_v, self.time_r
            )
        if len(self.state_ix):
            raw[self.state_ix] = np.where(
                self.state_is_state,
                states[self.state_el] == self.state_code,
                transitions[self.state_el] == self.state_code,
            )
        if len(self.rows):
            self._entity_conditions(snap, active, raw)
        return self._triggers(raw, active)

    def _entity_conditions(self, snap: Snapshot, active: np.ndarray, raw: np.ndarray) -> None:
        """Entity conditions' values into ``raw``: each group of kinds measured in one pass
        over the rows of triggers being evaluated now, then one comparison of every row."""
        rows = self.rows
        on = active[self.row_trigger] | self.row_always
        if not on.any():
            return
        measured = np.full(len(rows), np.nan)
        for ix, kinds in self.groups:
            sel = ix[on[ix]]
            if not len(sel):
                continue
            if kinds is M.PAIR_KINDS:
                measured[sel] = M.pair_measures(snap, rows, sel)
            elif kinds is M.SINGLE_KINDS:
                measured[sel] = M.single_measures(snap, rows, sel)
            elif kinds is M.DURATION_KINDS:
                measured[sel] = M.duration_measures(snap, rows, sel, self.since)
            else:
                measured[sel] = M.point_measures(snap, rows, sel, self.resolve, self.fixed)
        res = compare(measured, rows.value, rows.rule)
        if len(self.collision_rows):
            sel = self.collision_rows[on[self.collision_rows]]
            res[sel] = M.collision_hits(snap, rows, sel)
        n = len(raw)
        hits = np.bincount(rows.owner, weights=res & on, minlength=n)
        count = np.bincount(rows.owner, weights=on, minlength=n)
        touched = count > 0
        ok = np.where(self.rule_any, hits > 0, hits == count)
        raw[touched] = ok[touched]

    def _triggers(self, raw: np.ndarray, active: np.ndarray) -> np.ndarray:
        on = active[self.cond_trigger]
        prev = self.prev
        cur = raw.astype(np.int8)
        rising = (prev == 0) & raw
        falling = (prev == 1) & ~raw
        edged = np.where(
            self.edge_none, raw, (rising & self.edge_rise) | (falling & self.edge_fall)
        )
        edged &= on
        self.prev = np.where(on, cur, np.int8(-1))
        if self.history.shape[1] == 1:  # no delays
            delayed = edged
        else:
            k = self.step_no % self.history.shape[1]
            self.history[:, k] = edged
            back = (self.step_no - self.delay_steps) % self.history.shape[1]
            delayed = self.history[self.cond_ix, back]
            delayed &= self.delay_steps <= self.step_no
        self.step_no += 1
        fired = np.zeros(self.n_triggers, dtype=bool)
        if len(raw):
            groups = np.logical_and.reduceat(delayed, self.group_starts)
            has = self.has_conditions
            fired[has] = np.logical_or.reduceat(groups, self.trigger_groups[has])
        return fired & active


_STATE_CODES = {
    "standbyState": 0,
    "runningState": 1,
    "completeState": 2,
    "startTransition": 3,
    "endTransition": 4,
    "stopTransition": 5,
    "skipTransition": 6,
}


def _param_holds(parameters: dict, b: ParameterCondition, where: str) -> bool:
    if b.parameter not in parameters:
        raise HiyariError(f"{where}: unknown parameter {b.parameter!r} in ParameterCondition")
    have = str(parameters[b.parameter])
    try:
        a, v = float(have), float(b.value)
        return bool(compare(np.array([a]), np.array([v]), np.array([_RULES.index(b.rule)]))[0])
    except ValueError:
        if b.rule == Rule.EQUAL_TO:
            return have == b.value
        if b.rule == Rule.NOT_EQUAL_TO:
            return have != b.value
        raise HiyariError(f"{where}: ParameterCondition {b.rule} needs numbers") from None


def _classify(b: object) -> tuple[int, object, float, Rule | None]:
    """(row kind, reference entity or None, value, rule) of an entity condition."""
    if isinstance(b, RelativeDistanceCondition):
        return M.REL_DIST, b.entity, b.value, b.rule
    if isinstance(b, TimeHeadwayCondition):
        return M.HEADWAY, b.entity, b.value, b.rule
    if isinstance(b, TimeToCollisionCondition):
        return (M.TTC if b.entity is not None else M.TTC_POINT), b.entity, b.value, b.rule
    if isinstance(b, RelativeSpeedCondition):
        return M.REL_SPEED, b.entity, b.value, b.rule
    if isinstance(b, DistanceCondition):
        return M.DISTANCE, None, b.value, b.rule
    if isinstance(b, ReachPositionCondition):
        return M.REACH, None, b.tolerance, Rule.LESS_OR_EQUAL
    if isinstance(b, SpeedCondition):
        return M.SPEED, None, b.value, b.rule
    if isinstance(b, AccelerationCondition):
        return M.ACCEL, None, b.value, b.rule
    if isinstance(b, StandStillCondition):
        return M.STANDSTILL, None, b.duration, Rule.GREATER_OR_EQUAL
    if isinstance(b, EndOfRoadCondition):
        return M.END_OF_ROAD, None, b.duration, Rule.GREATER_OR_EQUAL
    if isinstance(b, CollisionCondition):
        return M.COLLISION, b.entity, 0.0, None
    raise HiyariError(f"condition {type(b).__name__} is not supported")


def _table(rows: list[tuple]) -> EntityRows:
    """The row table of (owner, a, b, value, rule code, kind, body) tuples."""
    owner, a, b, value, rule, kind, bodies = (
        (list(col) for col in zip(*rows, strict=True)) if rows else [[]] * 7
    )
    return EntityRows(
        owner=np.array(owner, dtype=np.intp),
        a=np.array(a, dtype=np.intp),
        b=np.array(b, dtype=np.intp),
        value=np.array(value, dtype=float),
        rule=np.array(rule, dtype=np.intp),
        kind=np.array(kind, dtype=np.int8),
        freespace=np.array([getattr(x, "freespace", False) for x in bodies], dtype=bool),
        dtype=np.array(
            [_DTYPE.get(getattr(x, "distance_type", DistanceType.EUCLIDEAN), 0) for x in bodies],
            dtype=np.int8,
        ),
        road=np.array(
            [
                getattr(x, "coordinate_system", CoordinateSystem.ENTITY) != CoordinateSystem.ENTITY
                for x in bodies
            ],
            dtype=bool,
        ),
        body=list(bodies),
    )
