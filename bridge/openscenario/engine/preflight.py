"""Storyboard actions whose outcome the Init state already decides, checked when the engine
starts: an error the run would meet when such an action starts is met before the first step
(and by ``hiyari run --dry-run``), with the same message.

A SpeedAction's change is known before the run when its actor keeps its Init speed until the
action starts: the storyboard moves the actor (it is not the ego), no Init transition is still
running on it, no storyboard action gives it a controller, and the SpeedAction is its only
storyboard action that sets its speed (SpeedAction, LongitudinalDistanceAction,
FollowTrajectoryAction). A target relative to another entity is known when that entity keeps
its Init speed for the whole run (the same, with no speed-setting action at all). Example: the
ALKS cut-in at ``Ego_InitSpeed_Ve0_kph`` = 50 accelerates its cut-in car from 30 to 40 km/h
at a rate of 0 m/s², refused at start instead of when the car cuts in.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from hiyari.bridge.openscenario.engine.kernels.shapes import span
from hiyari.bridge.openscenario.model.actions import (
    AbsoluteSpeed,
    Action,
    ActivateControllerAction,
    AssignControllerAction,
    FollowTrajectoryAction,
    LongitudinalDistanceAction,
    SpeedAction,
)
from hiyari.bridge.openscenario.model.storyboard import Storyboard
from hiyari.errors import HiyariError

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine

_SETS_SPEED = (SpeedAction, LongitudinalDistanceAction, FollowTrajectoryAction)
_CONTROLLER = (AssignControllerAction, ActivateControllerAction)


def story_actions(storyboard: Storyboard, names: Sequence[str]) -> dict[str, list[Action]]:
    """Every story action each entity may execute (an action of a group that also selects
    its act's triggering entities counts for every entity)."""
    out: dict[str, list[Action]] = {n: [] for n in names}
    for story in storyboard.stories:
        for act in story.acts:
            for group in act.groups:
                actors = names if group.select_triggering else group.actors
                actions = [a for m in group.maneuvers for ev in m.events for a in ev.actions]
                for name in actors:
                    if name in out:
                        out[name].extend(actions)
    return out


def check_decided_actions(engine: ScenarioEngine) -> None:
    """Raise the HiyariError a run would raise when a decided SpeedAction starts (see the
    module docstring); call after the Init actions."""
    actions = story_actions(engine.scenario.storyboard, engine.names)
    steady = {n for n in engine.names if _keeps_init_speed(engine, n, actions[n])}
    constant = {n for n in steady if not any(isinstance(a.body, _SETS_SPEED) for a in actions[n])}
    for name in sorted(steady - constant):
        setting = [a for a in actions[name] if isinstance(a.body, _SETS_SPEED)]
        if len(setting) != 1 or not isinstance(setting[0].body, SpeedAction):
            continue
        action, body = setting[0], setting[0].body
        target = body.target
        if isinstance(target, AbsoluteSpeed):
            goal = target.value
        elif target.entity in constant:
            ref = engine.actors[target.entity].v
            goal = ref * target.value if target.kind == "factor" else ref + target.value
        else:
            continue
        dyn = body.dynamics
        try:
            span(dyn.shape, dyn.dimension, dyn.value, goal - engine.actors[name].v, "SpeedAction")
        except HiyariError as exc:
            raise HiyariError(f"{action.source or action.name}: {exc}") from None


def _keeps_init_speed(engine: ScenarioEngine, name: str, actions: list[Action]) -> bool:
    """Whether nothing but its own speed-setting actions changes ``name``'s speed."""
    return (
        name != engine.ego
        and engine.storyboard_drives(name)
        and engine.actors[name].long is None
        and not any(isinstance(a.body, _CONTROLLER) for a in actions)
    )
