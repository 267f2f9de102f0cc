"""LanePosition laneId="0": the centre lane, i.e. the road's reference line moved by the lane
offset (0 m wide), is a valid position (OpenDRIVE lane 0); and a condition position the road
does not have is refused by the dry run as by the run (before: lane 0 was refused, and only
once the run had started)."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import scenario_xml, teleport_speed, write

from hiyari.bridge.cli.main import main
from hiyari.bridge.loop.execute import execute
from hiyari.bridge.loop.spec import EgoSetup, model_spec
from hiyari.bridge.openscenario.xosc.reader import read_scenario


def _reach(lane: int) -> str:
    return f"""<ConditionGroup><Condition name="there" delay="0" conditionEdge="none"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Car"/></TriggeringEntities>
<EntityCondition><ReachPositionCondition tolerance="5"><Position><LanePosition roadId="0" laneId="{lane}" s="100"/></Position>
</ReachPositionCondition></EntityCondition></ByEntityCondition></Condition></ConditionGroup>"""


def _scenario(tmp_path: Path, lane: int) -> Path:
    init = teleport_speed("Ego", -5, 5.0, 0.0) + teleport_speed("Car", -3, 50.0, 10.0)
    return write(
        tmp_path / f"lane{lane}.xosc", scenario_xml({"Ego": "", "Car": ""}, init, stop=_reach(lane))
    )


def test_reach_a_centre_lane_position(tmp_path: Path) -> None:
    """The ALKS straight road has no lane offset: lane 0 at s = 100 is (100, 0). The Car's
    reference point drives y = -4.5 (lane -3's centre) from x = 50 at 10 m/s: within 5 m once
    |x - 100| <= sqrt(25 - 4.5^2) = 2.179 m, x >= 97.82 m, t >= 4.782 s: the state at t = 4.8 s
    fires the stop trigger (SUMO time runs one step, the Init state, ahead)."""
    res = execute(model_spec(read_scenario(_scenario(tmp_path, 0)), EgoSetup(perception="none")))
    assert res.stop_trigger
    assert res.sim_seconds == pytest.approx(4.8 + 0.05, abs=1e-6)


def test_dry_run_refuses_a_lane_the_road_lacks(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    """Lane 9 does not exist: the dry run stops with the run's one line (it used to pass)."""
    path = _scenario(tmp_path, 9)
    assert main(["run", str(path), "--dry-run", "-q"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "road 0 has no lane 9" in err[0], err
