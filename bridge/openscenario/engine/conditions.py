"""All trigger conditions of a storyboard, compiled into tables and evaluated together.

Every condition gets a row in the condition table; entity conditions become one row per
(condition, triggering entity) pair in the entity-row table (see ``measures``). A step is one
call of the compiled :func:`trigger_kernel.evaluate_triggers`: it measures only the rows of
triggers being evaluated now (durations are always tracked), compares, reduces rows to
conditions, applies edges and delays (tracked per condition while its trigger is active; the
first evaluation after activation has no edge) and reduces conditions to triggers (OR of AND
groups). Python prepares only what needs the scenario's objects: the positions of the active
point conditions, and the contact matrix when there are contacts.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from hiyari.bridge.openscenario.engine.frames.lane import in_lane_frame
from hiyari.bridge.openscenario.engine.frames.links import road_ahead
from hiyari.bridge.openscenario.engine.frames.trajectory import in_trajectory_frame
from hiyari.bridge.openscenario.engine.kernels import measures as M
from hiyari.bridge.openscenario.engine.kernels import trigger_kernel as K
from hiyari.bridge.openscenario.engine.kernels.measures import EntityRows
from hiyari.bridge.openscenario.engine.kernels.snapshot import Snapshot, gather_entities
from hiyari.bridge.openscenario.engine.kernels.tables import (
    ElementArrays,
    EntityFields,
    TriggerArrays,
)
from hiyari.bridge.openscenario.engine.positions import Pose
from hiyari.bridge.openscenario.engine.values import ValueStore
from hiyari.bridge.openscenario.model.conditions import (
    AccelerationCondition,
    AngleCondition,
    CollisionCondition,
    Condition,
    CoordinateSystem,
    DistanceCondition,
    DistanceType,
    Edge,
    EndOfRoadCondition,
    EntityCondition,
    OffroadCondition,
    ParameterCondition,
    ReachPositionCondition,
    RelativeAngleCondition,
    RelativeClearanceCondition,
    RelativeDistanceCondition,
    RelativeSpeedCondition,
    Rule,
    SimulationTimeCondition,
    SpeedCondition,
    StandStillCondition,
    StoryboardElementStateCondition,
    TimeHeadwayCondition,
    TimeOfDayCondition,
    TimeToCollisionCondition,
    TrafficSignalCondition,
    TrafficSignalControllerCondition,
    TraveledDistanceCondition,
    Trigger,
    VariableCondition,
)
from hiyari.errors import HiyariError
from hiyari.net.road.topology import RoadGraph

_RULES = list(Rule)
_EDGES = {Edge.NONE: 0, Edge.RISING: 1, Edge.FALLING: 2, Edge.RISING_OR_FALLING: 3}
_DTYPE = {DistanceType.EUCLIDEAN: 0, DistanceType.LONGITUDINAL: 1, DistanceType.LATERAL: 2}

__all__ = ["ConditionBank", "Snapshot"]


class ConditionBank:
    """Every condition of the storyboard's triggers, evaluated in one compiled pass."""

    def __init__(
        self,
        triggers: list[Trigger],
        entity_index: dict[str, int],
        element_index: Callable[[str, str, str], int],
        values: ValueStore,
        resolve: Callable[[object], Pose],
        dt: float,
    ) -> None:
        self.entity_index = entity_index
        self.values = values
        self.resolve = resolve
        self.conditions: list[Condition] = []
        cond_trigger: list[int] = []
        group_start, trigger_group = [], []
        for ti, trig in enumerate(triggers):
            trigger_group.append(len(group_start))
            for group in trig:
                if not group:
                    raise HiyariError("a ConditionGroup without conditions")
                group_start.append(len(self.conditions))
                for c in group:
                    self.conditions.append(c)
                    cond_trigger.append(ti)
        self.n_triggers = len(triggers)
        self.group_start = np.array([*group_start, len(self.conditions)], dtype=np.int64)
        self.trigger_group = np.array([*trigger_group, len(group_start)], dtype=np.int64)
        self.cond_trigger = np.array(cond_trigger, dtype=np.int64)
        self.prev = np.full(len(self.conditions), -1, dtype=np.int8)  # -1: not evaluated
        self._compile(element_index, dt)

    # ------------------------------------------------------------------ compile
    def _compile(self, element_index: Callable[[str, str, str], int], dt: float) -> None:
        n = len(self.conditions)
        cond = np.zeros((n, 7), dtype=np.int64)
        cond[:, K.C_TRIGGER] = self.cond_trigger
        self.time_value = np.zeros(n)
        self.static = np.zeros(n, dtype=bool)
        #: Conditions on variables / parameters: (condition index, kind, body, source).
        self.value_conditions: list[tuple[int, str, object, str]] = []
        #: Conditions measured in Python (relative clearance, traffic signals): (index,
        #: condition), set by ``python_eval`` (the engine's) before each evaluation of their
        #: trigger.
        self.python_conditions: list[tuple[int, Condition]] = []
        self.python_eval: Callable[[Condition], bool] | None = None
        rows: list[tuple] = []
        for i, c in enumerate(self.conditions):
            b = c.body
            cond[i, K.C_EDGE] = _EDGES[c.edge]
            if isinstance(b, SimulationTimeCondition):
                cond[i, K.C_KIND], cond[i, K.C_RULE] = K.TIME, _RULES.index(b.rule)
                self.time_value[i] = b.value
            elif isinstance(b, StoryboardElementStateCondition):
                self._check_state(b.state, c.source)
                cond[i, K.C_KIND] = K.STATE
                cond[i, K.C_ELEMENT] = element_index(b.element_type, b.element, c.source)
                cond[i, K.C_CODE] = _STATE_CODES[b.state]
            elif isinstance(b, ParameterCondition | VariableCondition):
                cond[i, K.C_KIND] = K.STATIC
                kind = "parameter" if isinstance(b, ParameterCondition) else "variable"
                self.value_conditions.append((i, kind, b, c.source))
            elif isinstance(
                b, TrafficSignalCondition | TrafficSignalControllerCondition | TimeOfDayCondition
            ):
                cond[i, K.C_KIND] = K.STATIC  # read from SUMO (python_eval) each step
                self.python_conditions.append((i, c))
            elif isinstance(b, EntityCondition) and (
                isinstance(
                    b.body, RelativeClearanceCondition | AngleCondition | RelativeAngleCondition
                )
                or (isinstance(b.body, CollisionCondition) and b.body.by_type is not None)
                or in_lane_frame(b.body)
                or in_trajectory_frame(b.body)
            ):
                cond[i, K.C_KIND] = K.STATIC  # measured in Python (python_eval) each step
                refs = getattr(b.body, "entities", ()) or (getattr(b.body, "entity", None),)
                for name in (*b.triggering, *refs):
                    if name is not None:
                        self._entity(name, c.source)
                self.python_conditions.append((i, c))
            elif isinstance(b, EntityCondition):
                cond[i, K.C_KIND], cond[i, K.C_RULE] = K.ENTITY, b.rule != "all"
                rows += self._entity_rows(i, c, b)
            else:
                raise HiyariError(f"{c.source}: condition {type(b).__name__} is not supported")
        delay = np.array([c.delay for c in self.conditions])
        cond[:, K.C_DELAY] = np.rint(delay / dt).astype(np.int64) if n else 0
        self.history = np.zeros((n, int(cond[:, K.C_DELAY].max()) + 1 if n else 1), dtype=bool)
        self.step_no = 0
        self.cond = cond
        self.rows = _table(rows)
        self.row_table = _row_table(self.rows)
        self.needs_road = bool((self.rows.road == M.ROAD_FRAME).any())
        self.needs_on_net = bool((self.rows.kind == M.END_OF_ROAD).any())
        self.needs_contacts = bool((self.rows.kind == M.COLLISION).any())
        self.row_trigger = self.cond_trigger[self.rows.owner]
        self.since = np.full((len(self.rows), 2), np.nan)  # tracked state per row
        self.points = np.full((len(self.rows), 4), np.nan)
        self.fixed: dict[int, tuple[float, float]] = {}
        self.point_rows = np.flatnonzero(np.isin(self.rows.kind, M.POINT_KINDS))
        self._no_contact = np.zeros((len(self.entity_index),) * 2, dtype=bool)
        # the kernel's work arrays and result, reused from step to step
        self._work = np.zeros((len(self.entity_index), M.N_FIELDS))
        self._counts = np.zeros((2, n), dtype=np.int64)
        self._flags = np.zeros((2, n), dtype=bool)
        self._fired = np.zeros(self.n_triggers, dtype=bool)
        #: The tables above as one table for the trigger kernel (updated in place; passed as
        #: ``tuple(arrays)``, see kernels.tables).
        self.arrays = TriggerArrays(
            self.cond, self.time_value, self.static, self.group_start, self.trigger_group,
            self.prev, self.history, self.row_table, self.rows.value, self.points, self.since,
            self._work, self._counts, self._flags, self._fired, np.full((0, 0, 2), np.nan),
        )  # fmt: skip
        self.n_fired = 0
        self._values_version = -1
        self.refresh_values()

    def link_roads(self, road_ids: list[str], graph: Callable[[], RoadGraph]) -> None:
        """The road-frame links table for roads ``road_ids`` (ActorTable codes; rebuilt when
        more roads are in use): road b's s in road a's frame as ``shift + sign * s``, from the
        way along the road links (``graph()``) between their s = 0 points (frames.links);
        NaN where no link joins them."""
        k = len(road_ids)
        if self.arrays.links.shape[0] == k:
            return
        links = np.full((k, k, 2), np.nan)
        g = graph() if k > 1 else None
        for i, a in enumerate(road_ids):
            links[i, i] = 0.0, 1.0
            for j, b in enumerate(road_ids):
                if i != j and g is not None:
                    x0, x1 = road_ahead(g, a, 0.0, 1.0, b, 0.0), road_ahead(g, a, 0.0, 1.0, b, 1.0)
                    if x0 == x0 and x1 == x1:  # NaN: no link joins them
                        links[i, j] = x0, round(x1 - x0)
        self.arrays = self.arrays._replace(links=links)

    def refresh_values(self) -> None:
        """Re-read the conditions on variables and parameters when a value changed (their
        truth is a static column of the condition table between changes)."""
        if self._values_version == self.values.version:
            return
        self._values_version = self.values.version
        for i, kind, b, where in self.value_conditions:
            name = b.parameter if kind == "parameter" else b.variable
            self.static[i] = self.values.holds(kind, name, b.rule, b.value, where)

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
        return K.road_entities(
            active, self.row_trigger, self.rows.road, self.rows.a, self.rows.b,
            len(self.entity_index),
        )  # fmt: skip

    @property
    def fired(self) -> np.ndarray:
        """(T,) bool: the triggers fired at the latest evaluation (updated in place)."""
        return self._fired

    @property
    def no_contact(self) -> np.ndarray:
        """(E, E) bool, all False: the contact matrix of a step without contacts."""
        return self._no_contact

    # ------------------------------------------------------------------ evaluate
    def evaluate(
        self,
        snap: Snapshot,
        active: np.ndarray,
        states: np.ndarray,
        transitions: np.ndarray,
        gather: tuple | None = None,
    ) -> np.ndarray:
        """Fired triggers (bool per trigger; an array reused by the next call) given which
        triggers are ``active``, element ``states`` (codes) and the ``transitions`` (codes)
        each element went through at the last update. ``gather``: the WorldState, gather and
        actor tables (plain tuples) of :func:`snapshot.gather_entities` filling ``snap``'s
        arrays, run first in the same compiled call (None: ``snap`` is filled). ``n_fired``:
        how many fired."""
        for i, ec in self.python_conditions:
            if active[self.cond_trigger[i]] and self.python_eval is not None:
                self.static[i] = self.python_eval(ec)
        contact = self._no_contact
        if snap.contacts:
            contact = np.zeros_like(self._no_contact)
            for pair in snap.contacts:
                i, j = (*pair, *pair)[:2]  # a pair, or one entity (a set of one)
                contact[i, j] = contact[j, i] = True
        ent = EntityFields(
            snap.present, snap.centre, snap.ref, snap.heading, snap.length, snap.width,
            snap.speed, snap.accel, snap.on_net, snap.road_s, snap.road_t, snap.road_dir,
            contact, snap.contact_any,
            snap.road_code if snap.road_code is not None else np.full(len(snap.heading), -1.0),
        )  # fmt: skip
        ent = tuple(ent)  # the kernels take tables as plain tuples (see kernels.tables)
        if len(self.point_rows):
            if gather is not None:  # the points need the entities' presence first
                gather_entities(*gather, ent)
                gather = None
            self._resolve_points(snap, active)
        if len(self._work) != len(snap.heading):
            self._work = np.zeros((len(snap.heading), M.N_FIELDS))
            self.arrays = self.arrays._replace(work=self._work)
        trig, el = tuple(self.arrays), tuple(ElementArrays(active, states, transitions))
        if gather is None:
            self.n_fired = K.evaluate_triggers(snap.time, self.step_no, trig, ent, el)
        else:
            self.n_fired = K.gather_and_evaluate(snap.time, self.step_no, *gather, trig, ent, el)
        self.step_no += 1
        return self._fired

    def resolve_fixed(self) -> None:
        """Resolve now the positions of the point rows that do not move with the entities:
        an error in one is met before the first step (and by ``hiyari run --dry-run``)."""
        for row in self.point_rows.tolist():
            pos = self.rows.body[row].position
            if row not in self.fixed and isinstance(pos, M.FIXED_POSITIONS):
                p = self.resolve(pos)
                self.fixed[row] = (p.x, p.y, p.s, p.t) if p.road else (p.x, p.y, math.nan, math.nan)

    def _resolve_points(self, snap: Snapshot, active: np.ndarray) -> None:
        """World x, y and road s, t (NaN off the roads) of the positions of the point rows
        evaluated now (NaN for absent entities); positions that do not move with the entities
        resolved once."""
        sel = self.point_rows[active[self.row_trigger[self.point_rows]]]
        self.points[:] = np.nan
        for row in sel.tolist():
            if not snap.present[self.rows.a[row]]:
                continue
            point = self.fixed.get(row)
            if point is None:
                pos = self.rows.body[row].position
                p = self.resolve(pos)
                point = (p.x, p.y, p.s, p.t) if p.road else (p.x, p.y, math.nan, math.nan)
                if isinstance(pos, M.FIXED_POSITIONS):
                    self.fixed[row] = point
            self.points[row] = point


_STATE_CODES = {
    "standbyState": 0,
    "runningState": 1,
    "completeState": 2,
    "startTransition": 3,
    "endTransition": 4,
    "stopTransition": 5,
    "skipTransition": 6,
}


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
    if isinstance(b, TraveledDistanceCondition):
        return M.TRAVELED, None, b.value, Rule.GREATER_OR_EQUAL
    if isinstance(b, EndOfRoadCondition | OffroadCondition):  # both: off the network
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
        dtype=np.array([_dtype(x) for x in bodies], dtype=np.int8),
        road=np.array(
            [_FRAME[getattr(x, "coordinate_system", CoordinateSystem.ENTITY)] for x in bodies],
            dtype=np.int8,
        ),
        body=list(bodies),
    )


#: A speed / acceleration direction's code in the rows' distance-type column.
_DIRECTION = {None: M.DIR_NONE, "longitudinal": M.DIR_LON, "lateral": M.DIR_LAT,
              "vertical": M.DIR_VERT}  # fmt: skip


def _dtype(body: object) -> int:
    """The distance-type column of a row: its distance type, or for a speed, acceleration or
    relative speed its direction."""
    if isinstance(body, SpeedCondition | AccelerationCondition | RelativeSpeedCondition):
        return _DIRECTION[body.direction]
    return _DTYPE.get(getattr(body, "distance_type", DistanceType.EUCLIDEAN), 0)


#: The kernels' frame of each coordinateSystem (lane and trajectory coordinates are
#: measured in Python: frames.lane, frames.trajectory).
_FRAME = {
    CoordinateSystem.ENTITY: M.ENTITY_FRAME,
    CoordinateSystem.ROAD: M.ROAD_FRAME,
    CoordinateSystem.WORLD: M.WORLD_FRAME,
}


def _row_table(rows: EntityRows) -> np.ndarray:
    """(R, 9) int64 columns of the entity rows for the kernel (see trigger_kernel)."""
    return (
        np.stack(
            [
                rows.owner,
                rows.a,
                rows.b,
                rows.rule,
                rows.kind,
                rows.freespace,
                rows.dtype,
                rows.road,
                np.isin(rows.kind, M.DURATION_KINDS)
                | (
                    (rows.kind == M.ACCEL) & np.isin(rows.dtype, (M.DIR_LAT, M.DIR_NONE))
                ),  # yaw rate
            ],  # fmt: skip
            axis=1,
        )
        .astype(np.int64)
        .reshape(len(rows), 9)
    )
