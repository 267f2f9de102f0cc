"""All trigger conditions of a storyboard, compiled into arrays and evaluated together.

Every condition gets an index; entity conditions become one row per (condition, triggering
entity) pair, grouped by kind, so that a step evaluates each kind with a few numpy operations
over all its rows, whatever the number of conditions. Edges and delays are tracked per
condition while its trigger is active (the first evaluation after activation has no edge).
Triggers (OR of AND groups) are reduced with ``reduceat`` over the condition order.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hiyari.bridge.scenario.engine.geometry import axis_gaps, box_corners, box_distance
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
from hiyari.bridge.scenario.model.positions import LanePosition, RoadPosition, WorldPosition
from hiyari.errors import HiyariError

_RULES = list(Rule)
_EDGES = {Edge.NONE: 0, Edge.RISING: 1, Edge.FALLING: 2, Edge.RISING_OR_FALLING: 3}
#: Speed below which an actor stands still, m/s.
STANDSTILL_SPEED = 0.01


_OPS = (np.greater, np.less, np.equal, np.greater_equal, np.less_equal, np.not_equal)


def compare(measured: np.ndarray, value: np.ndarray, rule: np.ndarray) -> np.ndarray:
    """Apply rule codes (indices into Rule) elementwise; NaN measures are False."""
    first = int(rule[0]) if len(rule) else 0
    if len(rule) and (rule == first).all():
        out = _OPS[first](measured, value)
    else:
        out = np.zeros(len(rule), dtype=bool)
        for code in np.unique(rule).tolist():
            m = rule == code
            out[m] = _OPS[code](measured[m], value[m])
    return out & ~np.isnan(measured)


@dataclass
class Snapshot:
    """What conditions read at one step: per entity (index in the scenario's entity order)
    the reference point, box centre, heading (rad), sizes (m), speed (m/s), acceleration,
    presence, road coordinates of the box centre, and the contacts (entity index pairs)."""

    time: float
    present: np.ndarray  # (E,) bool
    ref: np.ndarray  # (E, 2)
    centre: np.ndarray  # (E, 2)
    heading: np.ndarray
    length: np.ndarray
    width: np.ndarray
    speed: np.ndarray
    accel: np.ndarray
    on_net: np.ndarray  # (E,) bool: on a SUMO lane
    road_s: np.ndarray  # (E,) s of the box centre (nan: unknown)
    road_t: np.ndarray
    road_dir: np.ndarray  # (E,) +1 / -1 driving direction along s
    contacts: set[frozenset[int]]
    contact_any: np.ndarray  # (E,) bool


@dataclass
class _Rows:
    """Rows of one entity-condition kind."""

    owner: list[int]
    a: list[int]
    b: list[int]
    value: list[float]
    rule: list[int]
    extra: list[object]


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
        self.cond_trigger: list[int] = []
        group_starts, trigger_groups = [], []
        for ti, trig in enumerate(triggers):
            trigger_groups.append(len(group_starts))
            for group in trig:
                group_starts.append(len(self.conditions))
                for c in group:
                    self.conditions.append(c)
                    self.cond_trigger.append(ti)
        n = len(self.conditions)
        self.n_triggers = len(triggers)
        self.empty = np.array([len(t) == 0 for t in triggers], dtype=bool)
        self.group_starts = np.array(group_starts, dtype=np.intp)
        self.trigger_groups = np.array(trigger_groups, dtype=np.intp)
        self.cond_trigger_arr = np.array(self.cond_trigger, dtype=np.intp)
        self.edge = np.array([_EDGES[c.edge] for c in self.conditions], dtype=np.int8)
        self.prev = np.full(n, -1, dtype=np.int8)  # -1: not evaluated since activation
        self.value = np.zeros(n, dtype=bool)
        self._delays(dt)
        self._compile(element_index, parameters)

    # ------------------------------------------------------------------ compile
    def _delays(self, dt: float) -> None:
        d = np.array([c.delay for c in self.conditions])
        self.delay_steps = np.rint(d / dt).astype(np.int64) if len(d) else np.zeros(0, np.int64)
        size = int(self.delay_steps.max()) + 1 if len(d) else 1
        self.history = np.zeros((len(d), size), dtype=bool)
        self.step_no = 0

    def _compile(self, element_index: Callable[[str, str, str], int], parameters: dict) -> None:
        time_ix, time_v, time_r = [], [], []
        state_ix, state_el = [], []
        self.static = np.zeros(len(self.conditions), dtype=bool)
        self.static_mask = np.zeros(len(self.conditions), dtype=bool)
        self.rows: dict[str, _Rows] = {}
        for i, c in enumerate(self.conditions):
            b = c.body
            if isinstance(b, SimulationTimeCondition):
                time_ix.append(i), time_v.append(b.value), time_r.append(_RULES.index(b.rule))
            elif isinstance(b, StoryboardElementStateCondition):
                state_ix.append(i)
                state_el.append(element_index(b.element_type, b.element, c.source))
                self._check_state(b.state, c.source)
            elif isinstance(b, ParameterCondition):
                self.static_mask[i] = True
                self.static[i] = _param_holds(parameters, b, c.source)
            elif isinstance(b, EntityCondition):
                self._add_entity(i, c, b)
            else:
                raise HiyariError(f"{c.source}: condition {type(b).__name__} is not supported")
        self.time_ix = np.array(time_ix, dtype=np.intp)
        self.time_v, self.time_r = np.array(time_v), np.array(time_r, dtype=np.int8)
        self.state_ix = np.array(state_ix, dtype=np.intp)
        self.state_el = np.array(state_el, dtype=np.intp)
        self.state_code = np.array(
            [_STATE_CODES[self.conditions[i].body.state] for i in state_ix], dtype=np.int8
        )
        self.arrays = {k: _as_arrays(r) for k, r in self.rows.items()}
        self.needs_road = any(bool(a["road"].any()) for a in self.arrays.values())
        self.since = {k: np.full(len(r.owner), np.nan) for k, r in self.rows.items()}
        self.rule_any = np.array(
            [
                not (isinstance(c.body, EntityCondition) and c.body.rule == "all")
                for c in self.conditions
            ]
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

    def _add_entity(self, i: int, c: Condition, ec: EntityCondition) -> None:
        b = ec.body
        kind, other, value, rule, extra = _classify(b)
        if kind == "ttc" and b.entity is None:
            kind = "ttc_point"
        rows = self.rows.setdefault(kind, _Rows([], [], [], [], [], []))
        ref = self._entity(other, c.source) if isinstance(other, str) else -1
        for name in ec.triggering:
            rows.owner.append(i)
            rows.a.append(self._entity(name, c.source))
            rows.b.append(ref)
            rows.value.append(value)
            rows.rule.append(_RULES.index(rule) if rule is not None else 0)
            rows.extra.append(extra if extra is not None else b)

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
            st = self.state_code
            is_state = st < 3
            raw[self.state_ix] = np.where(
                is_state, states[self.state_el] == st, transitions[self.state_el] == st
            )
        for kind, arr in self.arrays.items():
            # only conditions of triggers being evaluated now (durations are always tracked)
            on = active[self.cond_trigger_arr[arr["owner"]]]
            if kind not in ("standstill", "endofroad") and not on.all():
                if not on.any():
                    continue
                arr = {k: v[on] for k, v in arr.items()}
            res = _KINDS[kind](self, kind, arr, snap)
            hits = np.bincount(arr["owner"], weights=res, minlength=len(raw))
            count = np.bincount(arr["owner"], minlength=len(raw))
            touched = count > 0
            ok = np.where(self.rule_any, hits > 0, hits == count)
            raw[touched] = ok[touched]
        return self._triggers(raw, active)

    def _triggers(self, raw: np.ndarray, active: np.ndarray) -> np.ndarray:
        on = active[self.cond_trigger_arr] if len(self.cond_trigger_arr) else np.zeros(0, bool)
        prev = self.prev
        cur = raw.astype(np.int8)
        rising = (prev == 0) & (cur == 1)
        falling = (prev == 1) & (cur == 0)
        edged = np.select(
            [self.edge == 0, self.edge == 1, self.edge == 2],
            [raw, rising, falling],
            rising | falling,
        )
        edged &= on
        self.prev = np.where(on, cur, -1).astype(np.int8)
        k = self.step_no % self.history.shape[1]
        self.history[:, k] = edged
        back = (self.step_no - self.delay_steps) % self.history.shape[1]
        delayed = self.history[np.arange(len(raw)), back]
        delayed &= self.delay_steps <= self.step_no
        self.step_no += 1
        fired = np.zeros(self.n_triggers, dtype=bool)
        if len(raw):
            groups = np.logical_and.reduceat(delayed, self.group_starts)
            has = np.flatnonzero(~self.empty)
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


def _classify(b: object) -> tuple[str, object, float, Rule | None, object]:
    """(kind, reference entity or None, value, rule, extra) of an entity condition."""
    if isinstance(b, RelativeDistanceCondition):
        return "reldist", b.entity, b.value, b.rule, None
    if isinstance(b, TimeHeadwayCondition):
        return "headway", b.entity, b.value, b.rule, None
    if isinstance(b, TimeToCollisionCondition):
        return "ttc", b.entity, b.value, b.rule, None
    if isinstance(b, RelativeSpeedCondition):
        return "relspeed", b.entity, b.value, b.rule, None
    if isinstance(b, DistanceCondition):
        return "distance", None, b.value, b.rule, None
    if isinstance(b, ReachPositionCondition):
        return "reach", None, b.tolerance, Rule.LESS_OR_EQUAL, None
    if isinstance(b, SpeedCondition):
        return "speed", None, b.value, b.rule, None
    if isinstance(b, AccelerationCondition):
        return "accel", None, b.value, b.rule, None
    if isinstance(b, StandStillCondition):
        return "standstill", None, b.duration, Rule.GREATER_OR_EQUAL, None
    if isinstance(b, EndOfRoadCondition):
        return "endofroad", None, b.duration, Rule.GREATER_OR_EQUAL, None
    if isinstance(b, CollisionCondition):
        return "collision", b.entity, 0.0, None, b
    raise HiyariError(f"condition {type(b).__name__} is not supported")


def _as_arrays(r: _Rows) -> dict[str, np.ndarray]:
    bodies = r.extra
    return {
        "owner": np.array(r.owner, dtype=np.intp),
        "a": np.array(r.a, dtype=np.intp),
        "b": np.array(r.b, dtype=np.intp),
        "value": np.array(r.value, dtype=float),
        "rule": np.array(r.rule, dtype=np.int8),
        "freespace": np.array([getattr(x, "freespace", False) for x in bodies], dtype=bool),
        "dtype": np.array(
            [_DTYPE.get(getattr(x, "distance_type", DistanceType.EUCLIDEAN), 0) for x in bodies],
            dtype=np.int8,
        ),
        "road": np.array(
            [
                getattr(x, "coordinate_system", CoordinateSystem.ENTITY) != CoordinateSystem.ENTITY
                for x in bodies
            ],
            dtype=bool,
        ),
        "body": np.array(bodies, dtype=object),
    }


_DTYPE = {DistanceType.EUCLIDEAN: 0, DistanceType.LONGITUDINAL: 1, DistanceType.LATERAL: 2}


def _pair_measure(
    snap: Snapshot, arr: dict, a: np.ndarray, b: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(distance, position of B ahead of A along A's axis or the road) per row, by distance
    type, freespace and coordinate system. Only the measures some row needs are computed."""
    fs, dtype, road = arr["freespace"], arr["dtype"], arr["road"]
    ent = np.full(len(a), np.nan)
    ahead = np.full(len(a), np.nan)
    ent_rows = ~road
    if ent_rows.any():
        ca, cb = snap.centre[a], snap.centre[b]
        ha, la, wa = snap.heading[a], snap.length[a], snap.width[a]
        corners_b = box_corners(cb, snap.heading[b], snap.length[b], snap.width[b])
        gx, gy, xmin, xmax = axis_gaps(ca, ha, la, wa, corners_b)
        ref_local = _local(snap.ref[b] - snap.ref[a], ha)
        ahead = 0.5 * (xmin + xmax)
        eu = np.hypot(ref_local[:, 0], ref_local[:, 1])
        need_box = ent_rows & fs & (dtype == 0)
        if need_box.any():
            eu = eu.copy()
            eu[need_box] = box_distance(box_corners(ca, ha, la, wa)[need_box], corners_b[need_box])
        ent = np.select(
            [dtype == 1, dtype == 2],
            [np.where(fs, gx, np.abs(ref_local[:, 0])), np.where(fs, gy, np.abs(ref_local[:, 1]))],
            eu,
        )
    if road.any():
        la = snap.length[a]
        ds = (snap.road_s[b] - snap.road_s[a]) * snap.road_dir[a]
        dt_ = snap.road_t[b] - snap.road_t[a]
        lon = np.where(fs, np.maximum(0.0, np.abs(ds) - 0.5 * (la + snap.length[b])), np.abs(ds))
        lat = np.where(
            fs, np.maximum(0.0, np.abs(dt_) - 0.5 * (snap.width[a] + snap.width[b])), np.abs(dt_)
        )
        rd = np.select([dtype == 1, dtype == 2], [lon, lat], np.hypot(lon, lat))
        ent = np.where(road, rd, ent)
        ahead = np.where(road, ds, ahead)
    return ent, ahead


def _local(d: np.ndarray, h: np.ndarray) -> np.ndarray:
    c, s = np.cos(h), np.sin(h)
    return np.stack([d[:, 0] * c + d[:, 1] * s, -d[:, 0] * s + d[:, 1] * c], 1)


def _present(snap: Snapshot, a: np.ndarray, b: np.ndarray | None = None) -> np.ndarray:
    ok = snap.present[a]
    if b is not None:
        ok = ok & (b >= 0) & snap.present[np.maximum(b, 0)]
    return ok


def _eval_reldist(bank: ConditionBank, kind: str, arr: dict, snap: Snapshot) -> np.ndarray:
    a, b = arr["a"], arr["b"]
    dist, _ = _pair_measure(snap, arr, a, b)
    return compare(np.where(_present(snap, a, b), dist, np.nan), arr["value"], arr["rule"])


def _eval_headway(bank: ConditionBank, kind: str, arr: dict, snap: Snapshot) -> np.ndarray:
    a, b = arr["a"], arr["b"]
    dist, ahead = _pair_measure(snap, arr, a, b)
    v = snap.speed[a]
    thw = np.where((ahead > 0) & (v > 1e-6), dist / np.maximum(v, 1e-6), np.inf)
    return compare(np.where(_present(snap, a, b), thw, np.nan), arr["value"], arr["rule"])


def _eval_ttc(bank: ConditionBank, kind: str, arr: dict, snap: Snapshot) -> np.ndarray:
    a, b = arr["a"], arr["b"]
    dist, _ = _pair_measure(snap, arr, a, b)
    va = snap.speed[a][:, None] * np.stack([np.cos(snap.heading[a]), np.sin(snap.heading[a])], 1)
    vb = snap.speed[b][:, None] * np.stack([np.cos(snap.heading[b]), np.sin(snap.heading[b])], 1)
    dtype, ha = arr["dtype"], snap.heading[a]
    axis_x = np.stack([np.cos(ha), np.sin(ha)], 1)
    axis_y = np.stack([-np.sin(ha), np.cos(ha)], 1)
    rel = snap.centre[b] - snap.centre[a]
    line = rel / np.maximum(np.linalg.norm(rel, axis=1), 1e-9)[:, None]
    direction = np.where(
        (dtype == 1)[:, None], axis_x, np.where((dtype == 2)[:, None], axis_y, line)
    )
    towards = np.sign(np.einsum("ij,ij->i", rel, direction))
    closing = np.einsum("ij,ij->i", va - vb, direction) * towards
    ttc = np.where(closing > 1e-9, dist / np.maximum(closing, 1e-9), np.inf)
    return compare(np.where(_present(snap, a, b), ttc, np.nan), arr["value"], arr["rule"])


def _eval_point(bank: ConditionBank, kind: str, arr: dict, snap: Snapshot) -> np.ndarray:
    """Distance / ReachPosition / TTC to a position, per row."""
    a = arr["a"]
    out = np.zeros(len(a), dtype=bool)
    for k, body in enumerate(arr["body"]):
        if not snap.present[a[k]]:
            continue
        p = bank.resolve(body.position)
        i = a[k]
        d = np.array([p.x, p.y]) - snap.ref[i]
        dist = math.hypot(*d)
        if kind in ("distance", "ttc_point") and body.freespace:
            corners = box_corners(
                snap.centre[i : i + 1],
                snap.heading[i : i + 1],
                snap.length[i : i + 1],
                snap.width[i : i + 1],
            )
            pt = np.repeat(np.array([[[p.x, p.y]]]), 4, axis=1)
            dist = float(box_distance(corners, pt)[0])
        if kind == "ttc_point":
            v = snap.speed[i] * np.array([math.cos(snap.heading[i]), math.sin(snap.heading[i])])
            closing = float(v @ d) / max(math.hypot(*d), 1e-9)
            dist = dist / closing if closing > 1e-9 else math.inf
        out[k] = bool(compare(np.array([dist]), arr["value"][k : k + 1], arr["rule"][k : k + 1])[0])
    return out


def _eval_single(bank: ConditionBank, kind: str, arr: dict, snap: Snapshot) -> np.ndarray:
    a = arr["a"]
    if kind == "speed":
        m = snap.speed[a]
    elif kind == "accel":
        m = snap.accel[a]
    elif kind == "relspeed":
        b = arr["b"]
        m = np.where(_present(snap, a, b), snap.speed[a] - snap.speed[np.maximum(b, 0)], np.nan)
    else:  # standstill / endofroad: time the state has lasted
        now = snap.speed[a] < STANDSTILL_SPEED if kind == "standstill" else ~snap.on_net[a]
        since = bank.since[kind]
        since[:] = np.where(
            now & snap.present[a], np.where(np.isnan(since), snap.time, since), np.nan
        )
        m = snap.time - since
    return compare(np.where(snap.present[a], m, np.nan), arr["value"], arr["rule"])


def _eval_collision(bank: ConditionBank, kind: str, arr: dict, snap: Snapshot) -> np.ndarray:
    a, b = arr["a"], arr["b"]
    out = np.zeros(len(a), dtype=bool)
    if not snap.contacts and not snap.contact_any.any():
        return out
    for k in range(len(a)):
        if b[k] >= 0:
            out[k] = frozenset((int(a[k]), int(b[k]))) in snap.contacts
        else:
            out[k] = bool(snap.contact_any[a[k]])
    return out


_KINDS = {
    "reldist": _eval_reldist,
    "headway": _eval_headway,
    "ttc": _eval_ttc,
    "relspeed": _eval_single,
    "distance": _eval_point,
    "reach": _eval_point,
    "ttc_point": _eval_point,
    "speed": _eval_single,
    "accel": _eval_single,
    "standstill": _eval_single,
    "endofroad": _eval_single,
    "collision": _eval_collision,
}

FIXED_POSITIONS = (WorldPosition, LanePosition, RoadPosition)
