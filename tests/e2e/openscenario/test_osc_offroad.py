"""OffroadCondition on SUMO: a scripted pedestrian walking away from the road across open
ground is off every road (no SUMO lane under it) from the step it leaves the last lane, and
the condition holds once that has lasted its duration."""

from __future__ import annotations

from pathlib import Path

import pytest
from openscenario_files import (
    run_scenario,
    scenario_xml,
    story,
    teleport_speed,
    write,
)

PED = """<Pedestrian name="p" mass="70" model="m" pedestrianCategory="pedestrian"><BoundingBox><Center x="0" y="0" z="0.9"/>
<Dimensions width="0.5" length="0.5" height="1.8"/></BoundingBox><Properties/></Pedestrian>"""
AWAY = """<RoutingAction><FollowTrajectoryAction><TimeReference><Timing domainAbsoluteRelative="absolute" scale="1" offset="0"/></TimeReference>
<TrajectoryFollowingMode followingMode="position"/><TrajectoryRef><Trajectory name="away" closed="false"><Shape><Polyline>
<Vertex time="0"><Position><WorldPosition x="100" y="-10" h="-1.5707963267948966"/></Position></Vertex>
<Vertex time="100"><Position><WorldPosition x="100" y="-1010" h="-1.5707963267948966"/></Position></Vertex>
</Polyline></Shape></Trajectory></TrajectoryRef></FollowTrajectoryAction></RoutingAction>"""


def _offroad(duration: float) -> str:
    return f"""<Condition name="off" delay="0" conditionEdge="rising"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Ped"/></TriggeringEntities>
<EntityCondition><OffroadCondition duration="{duration}"/></EntityCondition></ByEntityCondition></Condition>"""


def test_offroad_after_its_duration(tmp_path: Path) -> None:
    init = (
        teleport_speed("Ego", -4, 20, 10)
        + f'<Private entityRef="Ped"><PrivateAction>{AWAY}</PrivateAction></Private>'
    )
    stories = story("Ped", AWAY, _offroad(1.0), "Off")
    lanes = {}

    def on_step(sim, world, report, engine) -> None:
        lanes[round(report.time, 2)] = str(world.lane[world.index("Ped")])

    engine, _ = run_scenario(
        write(tmp_path / "o.xosc", scenario_xml({"Ego": "", "Ped": PED}, init, stories + "")),
        tmp_path,
        until=40.0,
        on_step=on_step,
    )
    left = min(
        t for t, ln in lanes.items() if ln == "" and all(lanes[u] == "" for u in lanes if u >= t)
    )
    started = [t for t, kind, n, tr in engine.tree.log if n == "OffE" and tr == "startTransition"]
    assert left > 0.2  # it starts on the road (its shoulder) and walks off it
    assert started and started[0] == pytest.approx(left + 1.0)
