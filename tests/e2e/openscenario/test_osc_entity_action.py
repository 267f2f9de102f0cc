"""EntityAction on SUMO: DeleteEntityAction takes an entity out (SUMO no longer has it, its
conditions see it absent), AddEntityAction puts it back at a position where it goes on with
its speed."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    global_story,
    run_scenario,
    scenario_xml,
    teleport_speed,
    write,
)


def test_delete_then_add_an_entity(tmp_path: Path) -> None:
    delete = '<EntityAction entityRef="Car"><DeleteEntityAction/></EntityAction>'
    add = """<EntityAction entityRef="Car"><AddEntityAction><Position>
<LanePosition roadId="0" laneId="-3" s="300"/></Position></AddEntityAction></EntityAction>"""
    stories = global_story("Del", delete, 0.99) + global_story("Add", add, 1.99)
    init = teleport_speed("Ego", -4, 20, 10) + teleport_speed("Car", -3, 100, 10)
    seen = {}

    def on_step(sim, world, report, engine) -> None:
        k = world.index("Car") if "Car" in world.ids else -1
        seen[round(report.time, 2)] = None if k < 0 else float(world.xyz[k, 0])

    run_scenario(
        write(tmp_path / "e.xosc", scenario_xml({"Ego": "", "Car": ""}, init, stories)),
        tmp_path,
        until=3.0,
        on_step=on_step,
    )
    assert seen[0.95] == pytest.approx(100 + 9.5 + 1.4)  # box centre 1.4 m ahead of the reference
    assert seen[1.05] is None and seen[1.95] is None  # gone from the step after the deletion
    # added at s = 300 at 2.0, driving on at 10 m/s: 0.5 m further at the next step
    assert seen[2.05] == pytest.approx(300.5 + 1.4, abs=1e-6)
    assert seen[2.55] == pytest.approx(305.5 + 1.4, abs=1e-6)
