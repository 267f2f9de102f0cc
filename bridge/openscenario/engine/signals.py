"""Traffic signals: OpenSCENARIO's signal and controller actions and conditions on the SUMO
traffic lights of the imported net (a signal or controller is named by its SUMO id)."""

from __future__ import annotations

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
