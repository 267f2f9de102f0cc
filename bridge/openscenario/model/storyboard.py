"""The storyboard: Init actions, then stories of acts, maneuver groups, maneuvers and events,
with start and stop triggers; and the whole scenario."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from hiyari.bridge.openscenario.model.actions import Action
from hiyari.bridge.openscenario.model.conditions import Trigger
from hiyari.bridge.openscenario.model.entities import Entity

__all__ = [
    "Act",
    "SignalController",
    "SignalPhase",
    "Event",
    "InitAction",
    "Maneuver",
    "ManeuverGroup",
    "Scenario",
    "Story",
    "Storyboard",
]


@dataclass(frozen=True)
class SignalPhase:
    """A phase of a signal controller: ``duration`` s, the ``states`` it gives signals
    ((signal, state) as in TrafficSignalStateAction) and ``group_state`` (the state of the
    whole traffic light named like the controller; '' for none)."""

    name: str
    duration: float
    states: tuple[tuple[str, str], ...] = ()
    group_state: str = ""


@dataclass(frozen=True)
class SignalController:
    """A traffic-signal controller the scenario defines (RoadNetwork/TrafficSignals): its
    phases cycle from scenario time ``delay`` s after the start of ``reference``'s cycle (its
    name; '' for the scenario's start)."""

    name: str
    phases: tuple[SignalPhase, ...]
    delay: float = 0.0
    reference: str = ""


@dataclass(frozen=True)
class InitAction:
    """An Init action on ``entity`` ('' for a global action), applied before the first
    step."""

    entity: str
    action: Action


@dataclass(frozen=True)
class Event:
    """Actions started together when ``start_trigger`` holds (no trigger: at once).
    ``priority``: override (stop the maneuver's running events), skip (wait while another
    runs), parallel. Runs up to ``max_executions`` times."""

    name: str
    actions: tuple[Action, ...]
    start_trigger: Trigger = ()
    priority: str = "override"
    max_executions: int = 1


@dataclass(frozen=True)
class Maneuver:
    """A set of events."""

    name: str
    events: tuple[Event, ...]


@dataclass(frozen=True)
class ManeuverGroup:
    """Maneuvers executed by ``actors`` (plus the triggering entities of the act's start
    trigger when ``select_triggering``)."""

    name: str
    actors: tuple[str, ...]
    maneuvers: tuple[Maneuver, ...]
    select_triggering: bool = False
    max_executions: int = 1


@dataclass(frozen=True)
class Act:
    """Maneuver groups started by ``start_trigger`` (none: at once), stopped by
    ``stop_trigger`` (none: never)."""

    name: str
    groups: tuple[ManeuverGroup, ...]
    start_trigger: Trigger = ()
    stop_trigger: Trigger = ()


@dataclass(frozen=True)
class Story:
    """A sequence of acts (they run in parallel, each on its own trigger)."""

    name: str
    acts: tuple[Act, ...]


@dataclass(frozen=True)
class Storyboard:
    """Init actions, stories, and the stop trigger that ends the scenario."""

    init: tuple[InitAction, ...]
    stories: tuple[Story, ...]
    stop_trigger: Trigger = ()


@dataclass(frozen=True)
class Scenario:
    """A concrete scenario: parameters resolved, catalogs expanded, SI units.

    ``ego`` names the entity driven by the ego stack (None: no ego); ``road_network`` is the
    OpenDRIVE file (None: the caller supplies the net). ``parameters``: the top-level
    parameters' values (canonical text) and ``parameter_types`` their declared types;
    ``variables``: the declared variables, name -> (type, initial value as canonical text).
    """

    name: str
    entities: tuple[Entity, ...]
    storyboard: Storyboard
    ego: str | None = None
    road_network: Path | None = None
    parameters: dict[str, object] = field(default_factory=dict)
    source: Path | None = None
    parameter_types: dict[str, str] = field(default_factory=dict)
    variables: dict[str, tuple[str, str]] = field(default_factory=dict)
    #: Monitors (MonitorDeclarations): name -> initial value.
    monitors: dict[str, bool] = field(default_factory=dict)
    signal_controllers: tuple[SignalController, ...] = ()

    def entity(self, name: str) -> Entity:
        """The entity called ``name``; KeyError when absent."""
        for e in self.entities:
            if e.name == name:
                return e
        raise KeyError(name)
