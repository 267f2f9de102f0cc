"""Executing global actions: one function per kind, each acting once (not per actor) and
ending at once (OpenSCENARIO: variable, parameter and environment actions are immediate)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING

from hiyari.bridge.openscenario.engine.signals import phase_index, sumo_state
from hiyari.bridge.openscenario.engine.traffic import Area, Sink, Source, Swarm
from hiyari.bridge.openscenario.model.global_actions import (
    AddEntityAction,
    DeleteEntityAction,
    Environment,
    EnvironmentAction,
    GlobalActionBody,
    ParameterModifyAction,
    ParameterSetAction,
    SetMonitorAction,
    TrafficAreaAction,
    TrafficSignalControllerAction,
    TrafficSignalStateAction,
    TrafficSinkAction,
    TrafficSourceAction,
    TrafficStopAction,
    TrafficSwarmAction,
    VariableModifyAction,
    VariableSetAction,
)
from hiyari.errors import HiyariError

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine

GLOBAL_KINDS = (
    VariableSetAction,
    VariableModifyAction,
    ParameterSetAction,
    ParameterModifyAction,
    EnvironmentAction,
    AddEntityAction,
    DeleteEntityAction,
    SetMonitorAction,
    TrafficSignalStateAction,
    TrafficSignalControllerAction,
    TrafficSourceAction,
    TrafficSinkAction,
    TrafficSwarmAction,
    TrafficAreaAction,
    TrafficStopAction,
)


def is_global(body: object) -> bool:
    """Whether an action body is a global action (run once, not per actor)."""
    return isinstance(body, GLOBAL_KINDS)


def run_global(engine: ScenarioEngine, body: GlobalActionBody, where: str) -> None:
    """Apply global action ``body`` (``where``: file:line for messages)."""
    run = _RUNNERS.get(type(body))
    if run is None:
        raise HiyariError(f"{where}: global action {type(body).__name__} is not supported")
    run(engine, body, where)


def _variable_set(engine: ScenarioEngine, b: VariableSetAction, where: str) -> None:
    engine.values.set("variable", b.variable, b.value, where)


def _variable_modify(engine: ScenarioEngine, b: VariableModifyAction, where: str) -> None:
    engine.values.modify("variable", b.variable, b.op, b.value, where)


def _parameter_set(engine: ScenarioEngine, b: ParameterSetAction, where: str) -> None:
    engine.values.set("parameter", b.parameter, b.value, where)


def _parameter_modify(engine: ScenarioEngine, b: ParameterModifyAction, where: str) -> None:
    engine.values.modify("parameter", b.parameter, b.op, b.value, where)


def _environment(engine: ScenarioEngine, b: EnvironmentAction, where: str) -> None:
    engine.environment = merge_environment(engine.environment, b.environment)


def merge_environment(old: Environment | None, new: Environment) -> Environment:
    """``new`` with the parts it does not give kept from ``old`` (an EnvironmentAction changes
    what it names)."""
    if old is None:
        return new
    return replace(
        new,
        time_of_day=new.time_of_day if new.time_of_day is not None else old.time_of_day,
        animated=new.animated if new.time_of_day is not None else old.animated,
        weather=new.weather if new.weather is not None else old.weather,
        road=new.road if new.road is not None else old.road,
    )


def _delete(engine: ScenarioEngine, b: DeleteEntityAction, where: str) -> None:
    engine.remove_entity(b.entity, where)


def _add(engine: ScenarioEngine, b: AddEntityAction, where: str) -> None:
    engine.add_entity(b.entity, engine.resolver.resolve(b.position), where)


def _monitor(engine: ScenarioEngine, b: SetMonitorAction, where: str) -> None:
    engine.values.set("monitor", b.monitor, "true" if b.value else "false", where)


def _signal(engine: ScenarioEngine, b: TrafficSignalStateAction, where: str) -> None:
    engine._sim.set_signal_state(b.signal, sumo_state(engine._sim, b.signal, b.state, where))


def _controller(engine: ScenarioEngine, b: TrafficSignalControllerAction, where: str) -> None:
    clock = engine.controllers.get(b.controller)
    if clock is not None:  # a controller of the scenario
        clock.jump(b.phase, engine.now, where)
        clock.update(engine._sim, engine.now, where)
        return
    engine._sim.set_signal_phase(
        b.controller, phase_index(engine._sim, b.controller, b.phase, where)
    )


def _traffic(engine: ScenarioEngine, b: object, where: str) -> None:
    kind = {
        TrafficSourceAction: Source,
        TrafficSinkAction: Sink,
        TrafficSwarmAction: Swarm,
        TrafficAreaAction: Area,
    }
    key = b.name or f"{where}#{len(engine.traffic)}"
    engine.traffic[key] = kind[type(b)](engine, b)


def _traffic_stop(engine: ScenarioEngine, b: TrafficStopAction, where: str) -> None:
    if b.name not in engine.traffic:
        raise HiyariError(
            f"{where}: TrafficStopAction: no traffic action called {b.name!r} runs "
            f"(running: {', '.join(engine.traffic) or 'none'})"
        )
    del engine.traffic[b.name]


_RUNNERS: dict[type, Callable[..., None]] = {
    TrafficSourceAction: _traffic,
    TrafficSinkAction: _traffic,
    TrafficSwarmAction: _traffic,
    TrafficAreaAction: _traffic,
    TrafficStopAction: _traffic_stop,
    TrafficSignalStateAction: _signal,
    TrafficSignalControllerAction: _controller,
    SetMonitorAction: _monitor,
    DeleteEntityAction: _delete,
    AddEntityAction: _add,
    VariableSetAction: _variable_set,
    VariableModifyAction: _variable_modify,
    ParameterSetAction: _parameter_set,
    ParameterModifyAction: _parameter_modify,
    EnvironmentAction: _environment,
}
