"""Traffic signals: OpenSCENARIO's signal and controller actions and conditions on the SUMO
traffic lights of the imported net (a signal, or a controller the scenario does not define, is
named by its SUMO id), and the signal controllers a scenario defines, cycling their phases."""

from __future__ import annotations

from hiyari.bridge.openscenario.model.storyboard import SignalController
from hiyari.errors import HiyariError
from hiyari.traffic.simulation import Simulation

#: OpenSCENARIO lamp triples (red;yellow;green) and SUMO's link letter for each.
_TRIPLES = {
    ("on", "off", "off"): "r",
    ("off", "on", "off"): "y",
    ("off", "off", "on"): "G",
    ("on", "on", "off"): "u",
    ("off", "off", "off"): "O",
    ("off", "on", "on"): "y",
    ("flashing", "off", "off"): "r",
    ("off", "flashing", "off"): "o",
}


def sumo_state(sim: Simulation, signal: str, state: str, where: str) -> str:
    """SUMO's state string for ``state`` on traffic light ``signal`` (a triple applies to
    every link)."""
    links = _links(sim, signal, where)
    if ";" not in state:
        if len(state) != len(links):
            raise HiyariError(
                f"{where}: traffic light {signal!r} has {len(links)} links, state {state!r} "
                f"gives {len(state)}"
            )
        return state
    words = tuple(w.strip() for w in state.split(";"))
    letter = _TRIPLES.get(words)
    if letter is None:
        raise HiyariError(
            f"{where}: signal state {state!r} is not a red;yellow;green triple hiyari maps"
        )
    return letter * len(links)


def phase_index(sim: Simulation, controller: str, phase: str, where: str) -> int:
    """Index of phase ``phase`` (name, else index) of traffic light ``controller``."""
    _links(sim, controller, where)
    names = sim.signal_phases(controller)
    if phase in names:
        return names.index(phase)
    if phase.isdigit() and int(phase) < len(names):
        return int(phase)
    raise HiyariError(
        f"{where}: traffic light {controller!r} has no phase {phase!r} "
        f"(phases: {', '.join(n or str(k) for k, n in enumerate(names))})"
    )


def _links(sim: Simulation, signal: str, where: str) -> str:
    states = sim.signal_states()
    if signal not in states:
        raise HiyariError(
            f"{where}: no traffic light {signal!r} in the net (its traffic lights: "
            f"{', '.join(sorted(states)) or 'none'})"
        )
    return states[signal]


class ControllerClock:
    """A signal controller of the scenario running: its phase now and the SUMO states it
    sets when a phase starts (a TrafficSignalControllerAction may jump to a phase)."""

    def __init__(self, c: SignalController, start: float) -> None:
        self.c = c
        self.phase, self.since = 0, start
        self.applied = -1

    def update(self, sim: Simulation, now: float, where: str) -> None:
        """Advance to scenario time ``now`` and apply the phase when it changed."""
        if now < self.since:
            return
        while now - self.since >= self.c.phases[self.phase].duration - 1e-9:
            self.since += self.c.phases[self.phase].duration
            self.phase = (self.phase + 1) % len(self.c.phases)
        if self.applied != self.phase:
            self.applied = self.phase
            p = self.c.phases[self.phase]
            for signal, state in p.states:
                sim.set_signal_state(signal, sumo_state(sim, signal, state, where))
            if p.group_state:
                sim.set_signal_state(
                    self.c.name, sumo_state(sim, self.c.name, p.group_state, where)
                )

    def jump(self, phase: str, now: float, where: str) -> None:
        """Switch to phase ``phase`` (name, else index) now."""
        names = [p.name for p in self.c.phases]
        if phase in names:
            k = names.index(phase)
        elif phase.isdigit() and int(phase) < len(names):
            k = int(phase)
        else:
            raise HiyariError(
                f"{where}: signal controller {self.c.name!r} has no phase {phase!r} "
                f"(phases: {', '.join(names)})"
            )
        self.phase, self.since, self.applied = k, now, -1

    def in_phase(self, phase: str) -> bool:
        """Whether the controller is in phase ``phase`` (name or index) now."""
        return phase in (self.c.phases[self.phase].name, str(self.phase))
