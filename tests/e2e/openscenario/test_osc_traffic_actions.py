"""Traffic actions as SUMO traffic on the ALKS straight road: a source inserts SUMO-driven
vehicles at its rate until a TrafficStopAction ends it, a sink takes them out near its
position, a swarm keeps its number of vehicles around the ego."""

from __future__ import annotations

from pathlib import Path

from openscenario_files import (
    global_story,
    run_scenario,
    scenario_xml,
    teleport_speed,
    write,
)


def _traffic(tmp_path: Path, stories: str, until: float) -> dict[float, dict[str, float]]:
    init = teleport_speed("Ego", -5, 20, 10)
    text = scenario_xml({"Ego": ""}, init, stories)
    seen: dict[float, dict[str, float]] = {}

    def on_step(sim, world, report, engine) -> None:
        seen[round(report.time, 2)] = {
            i: float(world.xyz[k, 0]) for k, i in enumerate(world.ids.tolist()) if i != "Ego"
        }

    run_scenario(write(tmp_path / "t.xosc", text), tmp_path, until=until, on_step=on_step)
    return seen


def test_source_sink_and_stop(tmp_path: Path) -> None:
    source = """<TrafficAction trafficName="src"><TrafficSourceAction radius="0" rate="2" speed="20">
<Position><LanePosition roadId="0" laneId="-3" s="100"/></Position></TrafficSourceAction></TrafficAction>"""
    sink = """<TrafficAction trafficName="snk"><TrafficSinkAction radius="15">
<Position><LanePosition roadId="0" laneId="-3" s="150"/></Position></TrafficSinkAction></TrafficAction>"""
    stop = '<TrafficAction trafficName="src"><TrafficStopAction/></TrafficAction>'
    stories = (
        global_story("Src", source, 0.0)
        + global_story("Snk", sink, 0.0)
        + global_story("Stop", stop, 1.99)
    )
    seen = _traffic(tmp_path, stories, 6.5)
    ids = set().union(*seen.values())
    # 2 a second from 0.05 s (at 0.55, 1.05, 1.55) until the stop at 2.0 s: 3 vehicles
    assert len(ids) == 3 and all(i.startswith("src#") for i in ids)
    assert max(max(v.values(), default=0.0) for v in seen.values()) < 150 - 15 + 20 * 0.05 + 5
    assert seen[6.0] == {}  # every one taken out by the sink


def test_swarm_around_the_ego(tmp_path: Path) -> None:
    swarm = """<TrafficAction trafficName="sw"><TrafficSwarmAction innerRadius="15" numberOfVehicles="5" offset="20"
semiMajorAxis="120" semiMinorAxis="15"><CentralObject entityRef="Ego"/><InitialSpeedRange lowerLimit="8" upperLimit="12"/>
<DirectionOfTravelDistribution same="1" opposite="0"/></TrafficSwarmAction></TrafficAction>"""
    seen = _traffic(tmp_path, global_story("Sw", swarm, 0.0), 3.5)
    assert len(seen[1.0]) == 5 and len(seen[3.0]) == 5
    # all around the ego (10 m/s from 20): within the ellipse along x
    ego_x = 20 + 10 * 3.0 + 1.4
    assert all(abs(x - (ego_x + 20)) <= 121 for x in seen[3.0].values())


def test_area_filled_on_a_road_range_and_kept_full(tmp_path: Path) -> None:
    area = """<TrafficAction trafficName="ar"><TrafficAreaAction numberOfEntities="4" continuous="true">
<TrafficDistribution><TrafficDistributionEntry weight="1"><EntityDistribution><EntityDistributionEntry weight="1">
<ScenarioObjectTemplate><Vehicle name="t" vehicleCategory="car"><BoundingBox><Center x="1.4" y="0" z="0.9"/>
<Dimensions width="1.9" length="4.6" height="1.5"/></BoundingBox><Performance maxSpeed="50" maxDeceleration="8" maxAcceleration="4"/>
<Axles><FrontAxle maxSteering="0.5" wheelDiameter="0.6" trackWidth="1.6" positionX="2.8" positionZ="0.3"/>
<RearAxle maxSteering="0" wheelDiameter="0.6" trackWidth="1.6" positionX="0" positionZ="0.3"/></Axles><Properties/></Vehicle>
</ScenarioObjectTemplate></EntityDistributionEntry></EntityDistribution></TrafficDistributionEntry></TrafficDistribution>
<TrafficArea><RoadRange><RoadCursor roadId="0" s="300"><Lane id="-3"/><Lane id="-4"/></RoadCursor>
<RoadCursor roadId="0" s="400"/></RoadRange></TrafficArea></TrafficAreaAction></TrafficAction>"""
    seen = _traffic(tmp_path, global_story("Ar", area, 0.0), 2.5)
    # 4 SUMO vehicles between s = 300 and 400 (box centres within 5 m of its spots); one that
    # drives out no longer counts and another takes its place
    for t in (1.0, 2.0):
        inside = [x for x in seen[t].values() if 295 <= x - 1.4 <= 400]
        assert len(inside) == 4 and all(i.startswith("ar#") for i in seen[t])
