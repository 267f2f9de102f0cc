"""The closed loop's view of a ScenarioEngine (every run is one): the storyboard steps on every
new state, the stop trigger ends the run, the scored gap and the settle rule come from the
run's Scoring."""

from __future__ import annotations

import logging
import math
from collections.abc import Callable

import numpy as np

from hiyari.bridge.loop.closed_loop import ScenarioHooks
from hiyari.bridge.openscenario.engine import ScenarioEngine, StepReport
from hiyari.bridge.openscenario.engine.global_actions import is_global
from hiyari.bridge.openscenario.model import actions as m
from hiyari.bridge.openscenario.model.scoring import Scoring
from hiyari.kinematics import Pose, bumper_gap, unrotate
from hiyari.traffic.simulation import Simulation
from hiyari.traffic.world_state import WorldState

_log = logging.getLogger(__name__)
_said: set[str] = set()  # dropped-action warnings already given in this process


class EngineHooks(ScenarioHooks):
    """The closed loop's view of a ScenarioEngine: it steps the storyboard on every new state,
    ends the run at the stop trigger, and says whether the stack drives the ego. ``scoring``:
    the scored gap is to its target, else to the nearest actor ahead in the ego's corridor
    (bumper to bumper); its conflict point and settle rule apply. Made after SUMO started:
    applies the Init actions (``engine.start``)."""

    def __init__(self, engine: ScenarioEngine, sim: Simulation, scoring: Scoring | None = None):
        self.engine = engine
        self.scoring = scoring or Scoring()
        self.ego_id = engine.ego or ""
        self.target_id = self.scoring.target
        self.conflict_point = self.scoring.conflict_point
        tree = engine.tree
        events = disturbance_events(engine)
        self._disturbance = {tree.elements[i].name for i in events}
        self._acts = {tree.elements[_act_of(tree, i)].name for i in events}
        self._armed = False  # an act holding a disturbance event has started
        self._disturbed = False
        self._log_seen = 0  # entries of the element log already looked at
        self.report: StepReport = engine.start(sim)
        for line in dropped_ego_actions(engine):
            if line not in _said:  # the runs of a grid share their file: said once
                _said.add(line)
                _log.warning(line)
        self.ego_requests: list[tuple[float, str]] = []
        self._stopped_at = math.nan

    def after_step(self, sim: Simulation, world: WorldState) -> bool:
        self.report = self.engine.step(sim, world)
        self.ego_requests.extend((self.report.time, n) for n in self.report.ego_requests)
        return self.report.finished

    def disturbance_started(self) -> bool:
        """True once an Event acting on an actor other than the ego has started
        (:func:`disturbance_events`)."""
        if not self._disturbed and self._disturbance:
            # start transitions in the element log, not states: the stop trigger ends every
            # element, started or not, and an instant action's event starts and ends at once
            log = self.engine.tree.log
            for _, kind, name, what in log[self._log_seen :]:
                if what == "startTransition":
                    self._armed |= kind == "act" and name in self._acts
                    self._disturbed |= kind == "event" and name in self._disturbance
            self._log_seen = len(log)
        return self._disturbed

    @property
    def has_disturbance(self) -> bool:
        """Whether this run has a disturbance: an act holding an Event on a non-ego actor
        started (an act whose start trigger never holds, as a file's variant switch, e.g. the
        Euro NCAP CCR file's braking act in a CCRs run, is not part of the run)."""
        return self._armed or self._disturbed

    def stack_drives_ego(self) -> bool:
        return not self.report.ego_storyboard_driven

    def drive_ego(self, sim: Simulation, ego_id: str, speed: float) -> None:
        self.engine.drive_ego(sim, speed)

    def sensed(self, world: WorldState) -> WorldState:
        hidden = self.engine.hidden_from_sensors()
        if not hidden:
            return world
        return world.select(~np.isin(world.ids, hidden))

    def done(self, world: WorldState, ego: Pose, script_time: float) -> bool:
        """True ``scoring.settle_after_stop`` s after the ego first stood still."""
        now, sc = self.report.time, self.scoring
        if ego.speed < 0.05 and now > sc.settle_from and not np.isfinite(self._stopped_at):
            self._stopped_at = now
        return now - self._stopped_at >= sc.settle_after_stop

    def gap_target(self, world: WorldState, row: int) -> int:
        if self.target_id:
            return super().gap_target(world, row)
        xy = world.xyz[:, :2]
        rel = unrotate(xy - xy[row], float(world.heading[row]))
        along, across = bumper_gap(
            rel, world.length[row], world.width[row], world.length, world.width
        )
        ahead = (across < 0) & (along > -world.length)
        ahead[row] = False
        if not ahead.any():
            return -1
        return int(np.flatnonzero(ahead)[np.argmin(along[ahead])])


#: Storyboard actions a stack-driven ego does not apply (a FollowTrajectoryAction is steered
#: by the stack; controller, visibility and light actions apply to any ego).
_EGO_DROPPED = (
    m.SpeedAction, m.RandomRouteAction, m.SpeedProfileAction, m.LateralDistanceAction,
    m.SynchronizeAction, m.LongitudinalDistanceAction, m.LaneChangeAction, m.LaneOffsetAction,
    m.TeleportAction, m.AssignRouteAction, m.AcquirePositionAction,
)  # fmt: skip


def dropped_ego_actions(engine: ScenarioEngine) -> list[str]:
    """One warning line per kind of Event action addressed to the ego that the stack-driven
    ego will not apply (none when the storyboard drives the ego, or when the ego's controller
    asks for it with ``hiyari:driver = storyboard``, possibly activated later)."""
    sc, ego = engine.scenario, engine.ego
    if ego is None or engine.storyboard_drives(ego):
        return []
    entity = next((e for e in sc.entities if e.name == ego), None)
    if entity is not None and any(c.drives == "storyboard" for c in entity.controllers.values()):
        return []
    kinds: dict[str, list[str]] = {}
    for story in sc.storyboard.stories:
        for act in story.acts:
            for group in act.groups:
                if ego not in group.actors:
                    continue
                for man in group.maneuvers:
                    for ev in man.events:
                        for a in ev.actions:
                            if isinstance(a.body, _EGO_DROPPED):
                                kinds.setdefault(type(a.body).__name__, []).append(a.name)
    where = sc.source or sc.name
    return [
        f"{where}: {len(names)} {kind}(s) on the ego {ego!r} not applied ({', '.join(names)}): "
        "the ego is driven by hiyari's stack (give its controller the property "
        "hiyari:driver=storyboard to have the storyboard drive it)"
        for kind, names in kinds.items()
    ]


def disturbance_events(engine: ScenarioEngine) -> np.ndarray:
    """Element indices of the storyboard's Events that act on an actor other than the ego:
    a private action of a maneuver group with such an actor (or one that selects the act's
    triggering entities). Global actions (environment, variables, traffic) are left out:
    they set the scene, the disturbance is what another road user does."""
    tree, ego = engine.tree, engine.ego
    out = []
    for ev in tree.of_kind("event"):
        if ev.index == tree.init_event:
            continue
        group = tree.elements[tree.elements[ev.parent].parent].model
        others = [a for a in group.actors if a != ego] or group.select_triggering
        private = any(not is_global(tree.elements[a].model.body) for a in ev.children)
        if others and private:
            out.append(ev.index)
    return np.array(out, dtype=np.intp)


def _act_of(tree: object, i: int) -> int:
    """The act holding element ``i``."""
    while tree.elements[i].kind != "act":
        i = tree.elements[i].parent
    return i


#: Builds a run's hooks from its engine, SUMO (started) and scoring: EngineHooks, or a
#: subclass that adds to the scenario (the catalogue's commanded ego lane change).
HooksFactory = Callable[[ScenarioEngine, Simulation, Scoring], EngineHooks]
