"""Traffic-signal actions and conditions on a SUMO traffic light: the town junction of
tests/support/xodr_authoring signalised by netconvert; TrafficSignalStateAction (SUMO letters and
OpenSCENARIO lamp triples), TrafficSignalControllerAction (a phase by index) and the two
conditions reading them back; an unknown signal is one line naming the file."""

from __future__ import annotations

from pathlib import Path

import openscenario_files as F
import pytest
from xodr_authoring import town_map

from hiyari.errors import HiyariError
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.sumo_tools import run_sumo_tool


def _net(tmp_path: Path) -> tuple[Path, str]:
    xodr = town_map(tmp_path / "town.xodr")
    plain = import_opendrive(xodr, tmp_path / "town.net.xml")
    signalised = tmp_path / "town_tls.net.xml"
    run_sumo_tool(
        "netconvert", ["-s", str(plain), "--tls.set", "100", "-o", str(signalised)], "tls"
    )
    F.NETS[xodr.resolve()] = signalised  # the engine runs on the signalised net
    return xodr, "100"


def _global(name: str, action: str, t: float) -> str:
    return f"""<Story name="{name}S"><Act name="{name}A"><ManeuverGroup maximumExecutionCount="1" name="{name}G">
<Actors selectTriggeringEntities="false"/><Maneuver name="{name}M"><Event name="{name}" priority="override">
<Action name="{name}Action"><GlobalAction><InfrastructureAction><TrafficSignalAction>{action}</TrafficSignalAction>
</InfrastructureAction></GlobalAction></Action><StartTrigger><ConditionGroup>{F.time_condition(t, name + "t", "none")}</ConditionGroup>
</StartTrigger></Event></Maneuver></ManeuverGroup><StartTrigger><ConditionGroup>{F.time_condition(0, name + "g", "none")}</ConditionGroup></StartTrigger></Act></Story>"""


def _watch(name: str, body: str) -> str:
    never = '<Condition name="never" delay="0" conditionEdge="none"><ByValueCondition><SimulationTimeCondition value="1000" rule="greaterThan"/></ByValueCondition></Condition>'
    return f'<ConditionGroup><Condition name="{name}" delay="0" conditionEdge="none"><ByValueCondition>{body}</ByValueCondition></Condition>{never}</ConditionGroup>'


def test_signal_actions_and_conditions(tmp_path: Path) -> None:
    xodr, tls = _net(tmp_path)
    init = F.teleport_speed("Ego", -1, 10, 5).replace('roadId="0"', 'roadId="1"')
    stories = _global("Red", f'<TrafficSignalStateAction name="{tls}" state="on;off;off"/>', 0.99)
    stories += _global(
        "Phase",
        f'<TrafficSignalControllerAction trafficSignalControllerRef="{tls}" phase="0"/>',
        1.99,
    )
    stop = _watch("red", f'<TrafficSignalCondition name="{tls}" state="on;off;off"/>')
    stop += _watch(
        "p0", f'<TrafficSignalControllerCondition trafficSignalControllerRef="{tls}" phase="0"/>'
    )
    text = F.scenario_xml({"Ego": ""}, init, stories, stop, road=xodr)
    seen = {}

    def on_step(sim, world, report, engine) -> None:
        vals = {c.name: bool(engine.bank.static[i]) for i, c in enumerate(engine.bank.conditions)}
        seen[round(report.time, 2)] = (sim.signal_states([tls])[tls], vals["red"], vals["p0"])

    F.run_scenario(F.write(tmp_path / "s.xosc", text), tmp_path, until=2.5, on_step=on_step)
    state, red, _ = seen[1.05]
    assert set(state) == {"r"} and red  # every link red from the step after the action
    assert seen[2.05][2]  # phase 0 after the controller action
    assert not seen[2.05][1] or set(seen[2.05][0]) == {"r"}


def test_unknown_signal(tmp_path: Path) -> None:
    xodr, _ = _net(tmp_path)
    init = F.teleport_speed("Ego", -1, 10, 5).replace('roadId="0"', 'roadId="1"')
    text = F.scenario_xml(
        {"Ego": ""},
        init,
        _global("Red", '<TrafficSignalStateAction name="nope" state="GGG"/>', 0.5),
        road=xodr,
    )
    with pytest.raises(
        HiyariError,
        match=r"s\.xosc:\d+: no traffic light 'nope' in the net \(its traffic lights: 100\)",
    ):
        F.run_scenario(F.write(tmp_path / "s.xosc", text), tmp_path, until=1.0)


def test_scenario_signal_controller_cycles_and_jumps(tmp_path: Path) -> None:
    xodr, tls = _net(tmp_path)
    controller = f"""<TrafficSignals><TrafficSignalController name="ctl" delay="0.5">
<Phase name="stop" duration="1"><TrafficSignalState trafficSignalId="{tls}" state="on;off;off"/></Phase>
<Phase name="go" duration="2"><TrafficSignalState trafficSignalId="{tls}" state="off;off;on"/></Phase>
</TrafficSignalController></TrafficSignals>"""
    init = F.teleport_speed("Ego", -1, 10, 5).replace('roadId="0"', 'roadId="1"')
    jump = _global(
        "Jump",
        '<TrafficSignalControllerAction trafficSignalControllerRef="ctl" phase="stop"/>',
        2.49,
    )
    stop = _watch(
        "p", '<TrafficSignalControllerCondition trafficSignalControllerRef="ctl" phase="go"/>'
    )
    text = F.scenario_xml({"Ego": ""}, init, jump, stop, road=xodr)
    text = text.replace("</RoadNetwork>", controller + "</RoadNetwork>")
    seen = {}

    def on_step(sim, world, report, engine) -> None:
        vals = {c.name: bool(engine.bank.static[i]) for i, c in enumerate(engine.bank.conditions)}
        seen[round(report.time, 2)] = (set(sim.signal_states([tls])[tls]), vals["p"])

    F.run_scenario(F.write(tmp_path / "c.xosc", text), tmp_path, until=5.0, on_step=on_step)
    # from 0.5 s: stop 1 s, go 2 s; a jump back to stop at 2.5 s; SUMO shows a state set at t
    # from the step after
    assert seen[1.05][0] == {"r"} and seen[1.55][0] == {"G"} and seen[1.55][1]
    assert seen[2.55][0] == {"r"} and not seen[2.55][1]
    assert seen[3.55][0] == {"G"}  # 1 s after the jump: go again
