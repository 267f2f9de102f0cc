"""EnvironmentAction: an Environment inline or from a catalog (expressions in its own
parameter scope), time of day, sun, fog, precipitation and road friction held by the engine;
a later action replaces only the parts it gives."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from openscenario_files import (
    run_scenario,
    scenario_xml,
    teleport_speed,
    time_condition,
    write,
)

from hiyari.bridge.openscenario.xosc.reader import read_scenario

CATALOG = """<?xml version="1.0"?>
<OpenSCENARIO><FileHeader revMajor="1" revMinor="3" date="2026-01-01T00:00:00" description="c" author="t"/>
<Catalog name="Environments">
<Environment name="Dusk"><ParameterDeclarations><ParameterDeclaration name="el" parameterType="double" value="5"/></ParameterDeclarations>
<TimeOfDay animation="false" dateTime="2026-06-21T21:30:00"/>
<Weather fractionalCloudCover="twoOktas" temperature="290"><Sun azimuth="${300*pi/180}" elevation="${$el*pi/180}" illuminance="400"/>
<Precipitation precipitationType="rain" precipitationIntensity="2.5"/></Weather>
<RoadCondition frictionScaleFactor="0.7" wetness="wetWithPuddles"/></Environment>
</Catalog></OpenSCENARIO>"""

FOG = """<GlobalAction><EnvironmentAction><Environment name="Fog">
<Weather><Fog visualRange="80"/></Weather></Environment></EnvironmentAction></GlobalAction>"""


def test_environment_from_catalog_then_partly_replaced(tmp_path: Path) -> None:
    (tmp_path / "env").mkdir()
    write(tmp_path / "env" / "Environments.xosc", CATALOG)
    init = """<GlobalAction><EnvironmentAction><CatalogReference catalogName="Environments" entryName="Dusk">
<ParameterAssignments><ParameterAssignment parameterRef="el" value="3"/></ParameterAssignments>
</CatalogReference></EnvironmentAction></GlobalAction>""" + teleport_speed("Ego", -1, 50, 10)
    stories = f"""<Story name="S"><Act name="A"><ManeuverGroup maximumExecutionCount="1" name="G">
<Actors selectTriggeringEntities="false"/><Maneuver name="M"><Event name="E" priority="override">
<Action name="fog">{FOG}</Action><StartTrigger><ConditionGroup>{time_condition(0.99)}</ConditionGroup></StartTrigger>
</Event></Maneuver></ManeuverGroup><StartTrigger><ConditionGroup>{time_condition(0, "go", "none")}</ConditionGroup></StartTrigger></Act></Story>"""
    catalogs = f'<EnvironmentCatalog><Directory path="{tmp_path / "env"}"/></EnvironmentCatalog>'
    path = write(tmp_path / "e.xosc", scenario_xml({"Ego": ""}, init, stories, catalogs=catalogs))
    env = read_scenario(path).storyboard.init[0].action.body.environment
    assert env.weather.sun.elevation == pytest.approx(3 * math.pi / 180)
    seen = []
    engine, _ = run_scenario(
        path, tmp_path, until=1.5, on_step=lambda s, w, r, e: seen.append((r.time, e.environment))
    )
    at_start, last = seen[0][1], seen[-1][1]
    assert at_start.time_of_day == "2026-06-21T21:30:00" and at_start.weather.fog is None
    assert at_start.road.friction_scale == 0.7 and at_start.weather.precipitation.intensity == 2.5
    # the fog action gives only weather: the time of day and road stay, the sun goes with the
    # old weather (a Weather element replaces the weather)
    assert last.weather.fog.visual_range == 80 and last.weather.sun is None
    assert last.road.friction_scale == 0.7 and last.time_of_day == "2026-06-21T21:30:00"
