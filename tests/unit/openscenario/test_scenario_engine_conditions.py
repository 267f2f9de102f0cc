"""Condition edges and delays, evaluated by the engine's condition bank step by step."""

from __future__ import annotations

import numpy as np

from hiyari.bridge.openscenario.engine.conditions import ConditionBank, Snapshot
from hiyari.bridge.openscenario.engine.values import ValueStore
from hiyari.bridge.openscenario.model import Condition, Edge, Rule, SimulationTimeCondition

NO_VALUES = ValueStore({}, {}, {})  # no variables or parameters

DT = 0.1


def _snap(t: float) -> Snapshot:
    z = np.zeros(0)
    return Snapshot(t, np.zeros(0, bool), np.zeros((0, 2)), np.zeros((0, 2)), z, z, z, z, z,
                    np.zeros(0, bool), z, z, z, set(), np.zeros(0, bool))  # fmt: skip


def _fired(edge: Edge, delay: float = 0.0, active_from: float = 0.0) -> list[float]:
    """Times at which a one-condition trigger fires for 'time in [1, 2)' (time > 1 and a
    second condition time < 2, as one AND group: the value rises at 1.1 and falls at 2.0)."""
    up = Condition("up", SimulationTimeCondition(1.0, Rule.GREATER_THAN), edge, delay)
    down = Condition("down", SimulationTimeCondition(2.0, Rule.LESS_THAN), Edge.NONE, delay)
    trig = ((up, down),) if edge != Edge.FALLING else ((up,),)
    if edge == Edge.FALLING:  # falls when time < 2 stops holding
        trig = ((Condition("f", SimulationTimeCondition(2.0, Rule.LESS_THAN), edge, delay),),)
    if edge == Edge.RISING_OR_FALLING:
        trig = ((Condition("rf", SimulationTimeCondition(1.0, Rule.GREATER_THAN), edge, delay),),)
    bank = ConditionBank([trig], {}, lambda *a: 0, NO_VALUES, lambda p: None, DT)
    out = []
    for k in range(40):
        t = round(k * DT, 10)
        active = np.array([t >= active_from - 1e-9])
        if bank.evaluate(_snap(t), active, np.zeros(0, np.int8), np.zeros(0, np.int8))[0]:
            out.append(t)
    return out


def test_edges() -> None:
    assert _fired(Edge.NONE) == [round(1.1 + k * DT, 10) for k in range(9)]
    assert _fired(Edge.RISING) == [1.1]
    assert _fired(Edge.FALLING) == [2.0]
    assert _fired(Edge.RISING_OR_FALLING) == [1.1]


def test_delay_shifts_the_edge() -> None:
    assert _fired(Edge.RISING, delay=0.5) == [1.6]


def test_rising_edge_needs_a_false_value_after_activation() -> None:
    """A trigger activated while its condition already holds does not see a rising edge."""
    assert _fired(Edge.RISING, active_from=1.5) == []
    assert _fired(Edge.NONE, active_from=1.5)[0] == 1.5
