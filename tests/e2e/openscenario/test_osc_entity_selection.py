"""EntitySelection: a named selection (members by name, nested selections, by type) stands
for its entities as maneuver-group actors and triggering entities."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.bridge.openscenario.xosc.reader import read_scenario
from hiyari.errors import HiyariError

STOP = """<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="0"/></SpeedActionTarget></SpeedAction></LongitudinalAction>"""
SELECTIONS = """<EntitySelection name="pair"><Members><EntityRef entityRef="A"/><EntityRef entityRef="B"/></Members></EntitySelection>
<EntitySelection name="nested"><Members><EntityRef entityRef="pair"/><EntityRef entityRef="C"/></Members></EntitySelection>
<EntitySelection name="cars"><Members><ByType objectType="vehicle"/></Members></EntitySelection>"""


def _file(tmp_path: Path, selections: str) -> Path:
    init = (
        teleport_speed("Ego", -5, 20, 10)
        + teleport_speed("A", -4, 60, 10)
        + teleport_speed("B", -3, 60, 10)
    )
    init += teleport_speed("C", -3, 120, 10)
    stories = story("pair", STOP, time_condition(0.99, "t", "none"), "Stop")
    text = scenario_xml({"Ego": "", "A": "", "B": "", "C": ""}, init, stories)
    return write(tmp_path / "s.xosc", text.replace("</Entities>", selections + "</Entities>"))


def test_selection_as_actors(tmp_path: Path) -> None:
    path = _file(tmp_path, SELECTIONS)
    sc = read_scenario(path)
    group = sc.storyboard.stories[0].acts[0].groups[0]
    assert group.actors == ("A", "B")
    engine, _ = run_scenario(path, tmp_path, until=2.0)
    assert (
        engine.actors["A"].v == 0.0 and engine.actors["B"].v == 0.0 and engine.actors["C"].v == 10.0
    )


def test_selection_members_by_type_and_nested(tmp_path: Path) -> None:
    from hiyari.bridge.openscenario.xosc import reader

    path = _file(tmp_path, SELECTIONS)
    for sel, want in (("nested", ("A", "B", "C")), ("cars", ("Ego", "A", "B", "C"))):
        text = path.read_text().replace(
            '<EntityRef entityRef="pair"/></Actors>', f'<EntityRef entityRef="{sel}"/></Actors>'
        )
        sc = read_scenario(write(tmp_path / f"{sel}.xosc", text))
        assert sc.storyboard.stories[0].acts[0].groups[0].actors == want
    assert reader.expand_selections(sc.storyboard, {}) is sc.storyboard


def test_unknown_member_is_one_line(tmp_path: Path) -> None:
    bad = '<EntitySelection name="x"><Members><EntityRef entityRef="Nope"/></Members></EntitySelection>'
    with pytest.raises(HiyariError, match=r"s\.xosc:\d+: no entity 'Nope' in the scenario"):
        read_scenario(_file(tmp_path, bad))
