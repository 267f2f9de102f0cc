"""The storyboard's runtime tree: one element per story, act, maneuver group, maneuver, event
and action, with OpenSCENARIO states (standby, running, complete) and the transitions each
went through at the latest update (start, end, stop, skip)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hiyari.bridge.openscenario.model.storyboard import Storyboard
from hiyari.errors import HiyariError
from hiyari.jit import njit

STANDBY, RUNNING, COMPLETE = 0, 1, 2
START, END, STOP, SKIP, NO_TRANSITION = 3, 4, 5, 6, 7
TRANSITION_NAMES = {
    START: "startTransition",
    END: "endTransition",
    STOP: "stopTransition",
    SKIP: "skipTransition",
}


@dataclass
class Element:
    """One storyboard element: ``kind`` as in StoryboardElementStateCondition (story, act,
    maneuverGroup, maneuver, event, action), its model object and its children's indices."""

    index: int
    kind: str
    name: str
    model: object
    parent: int
    children: list[int] = field(default_factory=list)
    start_trigger: int = -1  # index into the trigger list (-1: none)
    stop_trigger: int = -1


class ElementTree:
    """All elements of a storyboard in arrays of states and transitions."""

    def __init__(self, sb: Storyboard) -> None:
        self.elements: list[Element] = []
        self.triggers = [sb.stop_trigger]  # trigger 0: the storyboard's stop trigger
        self.init = self._add("story", "Init", None, -1)
        init_mg = self._add("maneuverGroup", "Init", None, self.init)
        init_man = self._add("maneuver", "Init", None, init_mg)
        self.init_event = self._add("event", "Init", None, init_man)
        for ia in sb.init:
            self._add("action", ia.action.name, ia, self.init_event)
        for story in sb.stories:
            si = self._add("story", story.name, story, -1)
            for act in story.acts:
                ai = self._add("act", act.name, act, si)
                self.elements[ai].start_trigger = self._trigger(act.start_trigger)
                self.elements[ai].stop_trigger = self._trigger(act.stop_trigger)
                for g in act.groups:
                    gi = self._add("maneuverGroup", g.name, g, ai)
                    for m in g.maneuvers:
                        mi = self._add("maneuver", m.name, m, gi)
                        for ev in m.events:
                            ei = self._add("event", ev.name, ev, mi)
                            self.elements[ei].start_trigger = self._trigger(ev.start_trigger)
                            for action in ev.actions:
                                self._add("action", action.name, action, ei)
        n = len(self.elements)
        self._by_kind: dict[str, list[Element]] = {}
        for e in self.elements:
            self._by_kind.setdefault(e.kind, []).append(e)
        self.parent = np.array([e.parent for e in self.elements], dtype=np.intp)
        self.state = np.zeros(n, dtype=np.int8)
        self.transition = np.full(n, NO_TRANSITION, dtype=np.int8)
        self.log: list[tuple[float, str, str, str]] = []
        #: Ends of each element so far, and of events the number after which they complete
        #: (0 for the other kinds: they complete at their first end).
        self.executions = np.zeros(n, dtype=np.int64)
        self.max_runs = np.array(
            [
                getattr(e.model, "max_executions", 1) if e.kind == "event" else 0
                for e in self.elements
            ],
            dtype=np.int64,
        )

    def _add(self, kind: str, name: str, model: object, parent: int) -> int:
        i = len(self.elements)
        self.elements.append(Element(i, kind, name, model, parent))
        if parent >= 0:
            self.elements[parent].children.append(i)
        return i

    def _trigger(self, trig: tuple) -> int:
        if not trig:
            return -1
        self.triggers.append(trig)
        return len(self.triggers) - 1

    def index(self, kind: str, name: str, where: str) -> int:
        """The element ``name`` of ``kind`` (for StoryboardElementStateConditions)."""
        for e in self.elements:
            if e.kind == kind and e.name == name:
                return e.index
        raise HiyariError(f"{where}: no storyboard element {kind} {name!r}")

    def of_kind(self, kind: str) -> list[Element]:
        """Elements of one kind, in storyboard order."""
        return self._by_kind.get(kind, [])

    # ------------------------------------------------------------------ transitions
    def start(self, i: int, now: float) -> None:
        """standby -> running."""
        self._mark(i, RUNNING, START, now)

    def end(self, i: int, now: float) -> None:
        """running -> complete (or back to standby when it may run again)."""
        self.executions[i] += 1
        again = self.executions[i] < self.max_runs[i]
        self._mark(i, STANDBY if again else COMPLETE, END, now)

    def stop(self, i: int, now: float) -> None:
        """Stop ``i`` and everything running or waiting below it."""
        for c in self.elements[i].children:
            if self.state[c] != COMPLETE:
                self.stop(c, now)
        if self.state[i] != COMPLETE:
            self._mark(i, COMPLETE, STOP, now)

    def skip(self, i: int, now: float) -> None:
        """An event that was due while another ran (priority skip)."""
        self.transition[i] = SKIP
        e = self.elements[i]
        self.log.append((now, e.kind, e.name, TRANSITION_NAMES[SKIP]))

    def _mark(self, i: int, state: int, transition: int, now: float) -> None:
        self.state[i] = state
        self.transition[i] = transition
        e = self.elements[i]
        self.log.append((now, e.kind, e.name, TRANSITION_NAMES[transition]))

    def all_children(self, i: int, state: int) -> bool:
        """Whether every child of ``i`` is in ``state``."""
        return all(self.state[c] == state for c in self.elements[i].children)


@njit(cache=True)
def ends_bottom_up(
    order: np.ndarray,
    state: np.ndarray,
    parent: np.ndarray,
    has_children: np.ndarray,
    executions: np.ndarray,
    max_runs: np.ndarray,
) -> np.ndarray:
    """The running elements with children whose children are all complete, in a bottom-up
    pass over ``order`` (element indices, events first and stories last): the elements
    :meth:`ElementTree.end` is to be called on, in that order. An element completing (its
    last run: ``executions`` + 1 not below ``max_runs``) may complete its parent later in
    the pass; nothing is changed here."""
    n = len(state)
    open_children = np.zeros(n, dtype=np.int64)
    for i in range(n):
        if parent[i] >= 0 and state[i] != COMPLETE:
            open_children[parent[i]] += 1
    out = np.empty(len(order), dtype=np.int64)
    m = 0
    for j in range(len(order)):
        i = order[j]
        if state[i] == RUNNING and has_children[i] and open_children[i] == 0:
            out[m] = i
            m += 1
            if executions[i] + 1 >= max_runs[i] and parent[i] >= 0:
                open_children[parent[i]] -= 1
    return out[:m]


@njit(cache=True)
def active_triggers(
    state: np.ndarray,
    act_ix: np.ndarray,
    act_start: np.ndarray,
    act_stop: np.ndarray,
    ev_ix: np.ndarray,
    ev_parent: np.ndarray,
    ev_trig: np.ndarray,
    n_triggers: int,
) -> np.ndarray:
    """(T,) the triggers evaluated in element ``state``: the storyboard's stop trigger (0),
    standby acts' start triggers, running acts' stop triggers, the start triggers of standby
    events whose maneuver runs (``*_ix``: the acts' / events' element indices; trigger -1:
    none)."""
    active = np.zeros(n_triggers, dtype=np.bool_)
    active[0] = True
    for j in range(len(act_ix)):
        s = state[act_ix[j]]
        t = act_start[j] if s == STANDBY else (act_stop[j] if s == RUNNING else -1)
        if t >= 0:
            active[t] = True
    for j in range(len(ev_ix)):
        if ev_trig[j] >= 0 and state[ev_ix[j]] == STANDBY and state[ev_parent[j]] == RUNNING:
            active[ev_trig[j]] = True
    return active
