"""Small OpenSCENARIO 1.3 files written by the tests (on the ALKS roads of ../shared)."""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from pathlib import Path

from paths import REPO_ROOT

from hiyari.checkout import shared_dir

# resolved: ../shared may be a symlink, and the reader reports resolved paths
SHARED = shared_dir(REPO_ROOT).resolve() / "data" / "openscenario"
ALKS = SHARED / "alks"
ROADS = ALKS / "road_networks"
STRAIGHT = ROADS / "alks_road_straight.xodr"

CAR = """<Vehicle name="{name}" vehicleCategory="car">
  <BoundingBox><Center x="1.4" y="0" z="0.9"/><Dimensions width="2.0" length="5.0" height="1.8"/></BoundingBox>
  <Performance maxSpeed="70" maxDeceleration="10" maxAcceleration="10"/>
  <Axles><FrontAxle maxSteering="0.5" wheelDiameter="0.8" trackWidth="1.68" positionX="2.98" positionZ="0.4"/>
  <RearAxle maxSteering="0" wheelDiameter="0.8" trackWidth="1.68" positionX="0" positionZ="0.4"/></Axles>
  <Properties/>
</Vehicle>"""


def scenario_xml(
    entities: dict[str, str],
    init: str,
    stories: str = "",
    stop: str = "",
    params: str = "",
    road: Path = STRAIGHT,
    catalogs: str = "",
    rev: int = 3,
    variables: str = "",
) -> str:
    """An OpenSCENARIO document: ``entities`` name -> object XML (CAR when empty);
    ``variables``: VariableDeclaration elements (none: no VariableDeclarations)."""
    objs = "\n".join(
        f'<ScenarioObject name="{n}">{body or CAR.format(name=n)}</ScenarioObject>'
        for n, body in entities.items()
    )
    stop_xml = f"<StopTrigger>{stop}</StopTrigger>" if stop else ""
    var_xml = f"<VariableDeclarations>{variables}</VariableDeclarations>" if variables else ""
    return f"""<?xml version="1.0" encoding="utf-8"?>
<OpenSCENARIO>
<FileHeader revMajor="1" revMinor="{rev}" date="2026-01-01T00:00:00" description="test" author="hiyari"/>
<ParameterDeclarations>{params}</ParameterDeclarations>{var_xml}
<CatalogLocations>{catalogs}</CatalogLocations>
<RoadNetwork><LogicFile filepath="{road}"/></RoadNetwork>
<Entities>{objs}</Entities>
<Storyboard><Init><Actions>{init}</Actions></Init>{stories}{stop_xml}</Storyboard>
</OpenSCENARIO>
"""


def teleport_speed(entity: str, lane: int, s: float, speed: float, offset: float = 0.0) -> str:
    """Init actions placing ``entity`` on road 0 at lane / s with a speed (step)."""
    return f"""<Private entityRef="{entity}">
<PrivateAction><TeleportAction><Position><LanePosition roadId="0" laneId="{lane}" offset="{offset}" s="{s}"/></Position></TeleportAction></PrivateAction>
<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="{speed}"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>
</Private>"""


def time_condition(t: float, name: str = "c", edge: str = "rising") -> str:
    """A SimulationTimeCondition (>= t)."""
    return f"""<Condition name="{name}" delay="0" conditionEdge="{edge}"><ByValueCondition>
<SimulationTimeCondition value="{t}" rule="greaterOrEqual"/></ByValueCondition></Condition>"""


def story(actor: str, action: str, condition: str, name: str = "S") -> str:
    """One story with one event running ``action`` (a PrivateAction body) on ``actor``."""
    return f"""<Story name="{name}"><Act name="{name}Act"><ManeuverGroup maximumExecutionCount="1" name="{name}G">
<Actors selectTriggeringEntities="false"><EntityRef entityRef="{actor}"/></Actors>
<Maneuver name="{name}M"><Event name="{name}E" priority="override"><Action name="{name}Action"><PrivateAction>{action}</PrivateAction></Action>
<StartTrigger><ConditionGroup>{condition}</ConditionGroup></StartTrigger></Event></Maneuver></ManeuverGroup>
<StartTrigger><ConditionGroup>{time_condition(0, name + "start", "none")}</ConditionGroup></StartTrigger></Act></Story>"""


def write(path: Path, text: str) -> Path:
    """Write ``text`` to ``path`` and return it."""
    path.write_text(text)
    return path


NETS: dict[Path, Path] = {}


def net_for(xodr: Path, workdir: Path) -> Path:
    """The SUMO net imported from ``xodr``, once per test process. The nets are kept in a
    folder of this process's own in the session's temporary folder (removed with it), not in
    ``workdir``: a passed test's tmp_path is removed when the test ends, and the next test
    would find its cached net gone."""
    from hiyari.net.sumo.opendrive import import_opendrive

    if xodr not in NETS:
        folder = Path(tempfile.mkdtemp(prefix="osc-nets-"))
        NETS[xodr] = import_opendrive(xodr, folder / f"{xodr.stem}.net.xml")
    return NETS[xodr]


def run_scenario(
    path: Path,
    workdir: Path,
    until: float = 60.0,
    dt: float = 0.05,
    on_step: Callable[..., None] | None = None,
) -> tuple:
    """Run the scenario in ``path`` on SUMO with the engine; the ego (stack-driven) is held at
    its Init speed by a stand-in (steering along a path the storyboard gives it). ``on_step(sim, world, report, engine)`` after every update.
    Returns (engine, last report)."""
    from hiyari.bridge.openscenario.engine import ScenarioEngine
    from hiyari.bridge.openscenario.xosc.reader import read_scenario
    from hiyari.net.road.opendrive_lanes import RoadLanes
    from hiyari.traffic.simulation import SimConfig, Simulation

    sc = read_scenario(path)
    net = net_for(sc.road_network, workdir)
    roads = RoadLanes.from_files(sc.road_network, net)
    with Simulation(SimConfig(net=net, step_length=dt)) as sim:
        engine = ScenarioEngine(sc, roads, dt)
        report = engine.start(sim)
        v0 = engine.actors[sc.ego].v if sc.ego else 0.0
        while not report.finished and sim.time < until - 1e-9:
            world = sim.step()
            report = engine.step(sim, world)
            if sc.ego and not report.ego_storyboard_driven:
                engine.drive_ego(sim, abs(v0))
            if on_step is not None:
                on_step(sim, world, report, engine)
    return engine, report


#: Top-level declarations with ConstraintGroups as the ALKS templates write them, whose bounds
#: are a literal, a parameter reference ($MaxSpeed = 20) and an expression (1.5 + 0.25 = 1.75),
#: and a string parameter with one group per allowed value (the groups are ORed).
CONSTRAINED_PARAMS = """
<ParameterDeclaration name="MaxSpeed" parameterType="double" value="20"/>
<ParameterDeclaration name="Speed" parameterType="double" value="10">
  <ConstraintGroup><ValueConstraint rule="greaterThan" value="0"/>
  <ValueConstraint rule="lessOrEqual" value="$MaxSpeed"/></ConstraintGroup>
</ParameterDeclaration>
<ParameterDeclaration name="Offset" parameterType="double" value="0">
  <ConstraintGroup><ValueConstraint rule="greaterThan" value="-1.75"/>
  <ValueConstraint rule="lessOrEqual" value="${1.5 + 0.25}"/></ConstraintGroup>
</ParameterDeclaration>
<ParameterDeclaration name="LaneId" parameterType="string" value="-1">
  <ConstraintGroup><ValueConstraint rule="equalTo" value="-1"/></ConstraintGroup>
  <ConstraintGroup><ValueConstraint rule="equalTo" value="-2"/></ConstraintGroup>
</ParameterDeclaration>"""


def constrained_template(folder: Path, stop_s: float = 0.5) -> Path:
    """A template scenario (as the ALKS *_template.xosc): one car placed and set to speed
    by its CONSTRAINED_PARAMS, ending at ``stop_s``."""
    init = """<Private entityRef="Ego">
<PrivateAction><TeleportAction><Position><LanePosition roadId="0" laneId="$LaneId" offset="$Offset" s="50"/></Position></TeleportAction></PrivateAction>
<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="$Speed"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>
</Private>"""
    stop = f"<ConditionGroup>{time_condition(stop_s, 'end')}</ConditionGroup>"
    text = scenario_xml({"Ego": ""}, init, stop=stop, params=CONSTRAINED_PARAMS)
    return write(folder / "constrained_template.xosc", text)


def distribution_xml(scenario: Path, body: str) -> str:
    """A ParameterValueDistribution file (as the ALKS *_variation.xosc) over ``scenario``;
    ``body`` is its <Deterministic> or <Stochastic> element."""
    return f"""<?xml version="1.0" encoding="utf-8"?>
<OpenSCENARIO>
<FileHeader revMajor="1" revMinor="3" date="2026-01-01T00:00:00" description="variation" author="hiyari"/>
<ParameterValueDistribution><ScenarioFile filepath="{scenario}"/>{body}</ParameterValueDistribution>
</OpenSCENARIO>
"""


#: Speed in {10, 30} x Offset in -1.75, 0, 1.75 (the first axis varies slowest): runs 0 and 3
#: break Offset > -1.75, runs 3, 4, 5 break Speed <= $MaxSpeed (20); runs 1 and 2 run.
DETERMINISTIC_VIOLATING = """<Deterministic>
<DeterministicSingleParameterDistribution parameterName="Speed"><DistributionSet>
<Element value="10"/><Element value="30"/></DistributionSet></DeterministicSingleParameterDistribution>
<DeterministicSingleParameterDistribution parameterName="Offset"><DistributionRange stepWidth="1.75">
<Range lowerLimit="-1.75" upperLimit="1.75"/></DistributionRange></DeterministicSingleParameterDistribution>
</Deterministic>"""


def stochastic_violating(n: int, seed: int) -> str:
    """``n`` draws of Offset uniform in [-3, 3] and LaneId from {-1, -3}: a run breaks the
    constraints when |Offset| passes 1.75 (-1.75 itself included) or LaneId is -3."""
    return f"""<Stochastic numberOfTestRuns="{n}" randomSeed="{seed}">
<StochasticDistribution parameterName="Offset"><UniformDistribution><Range lowerLimit="-3" upperLimit="3"/></UniformDistribution></StochasticDistribution>
<StochasticDistribution parameterName="LaneId"><ProbabilityDistributionSet><Element value="-1" weight="1"/><Element value="-3" weight="1"/></ProbabilityDistributionSet></StochasticDistribution>
</Stochastic>"""


def element_seeds(folder: Path) -> list[Path]:
    """Scenarios using elements that the ALKS and Euro NCAP sets do not (SpeedProfileAction
    with DynamicConstraints, a continuous LateralDistanceAction, RandomRouteAction through a
    junction, a timed NURBS followed with FollowTrajectoryAction, GeoPositions on a road with a
    geoReference, variables and the deprecated ParameterAction, a Clothoid and a Polyline
    trajectory, SynchronizeAction with a final speed, GlobalActions: EnvironmentAction,
    EntityAction delete / add, TrafficSwarm / Source / Sink / Stop actions), written into
    ``folder``: seeds for the fuzz suite. Each runs to its stop trigger unmutated
    (tests/e2e/openscenario/test_element_seeds.py)."""
    profile = """<LongitudinalAction><SpeedProfileAction followingMode="position">
<DynamicConstraints maxAcceleration="2" maxDeceleration="4"/>
<SpeedProfileEntry speed="14" time="2"/><SpeedProfileEntry speed="6"/></SpeedProfileAction></LongitudinalAction>"""
    keep = """<LateralAction><LateralDistanceAction entityRef="Ref" distance="1.0" freespace="true"
continuous="true" displacement="leftToReferencedEntity" coordinateSystem="entity"/></LateralAction>"""
    cars = {"Ego": "", "Car": ""}
    stop = f"<ConditionGroup>{time_condition(4.0, 'end')}</ConditionGroup>"
    go = time_condition(0.5, "go", "none")
    texts = {
        "speed_profile.xosc": scenario_xml(
            cars,
            teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -4, 50, 10),
            story("Car", profile, go, "P"),
            stop,
        ),
        "lateral_distance.xosc": scenario_xml(
            {"Ego": "", "Ref": "", "Car": ""},
            teleport_speed("Ego", -5, 20, 10) + teleport_speed("Ref", -4, 80, 10)
            + teleport_speed("Car", -3, 80, 10),
            story("Car", keep, go, "K"),
            stop,
        ),
        "random_route.xosc": scenario_xml(
            cars,
            teleport_speed("Ego", -1, 20, 5) + teleport_speed("Car", -1, 200, 10),
            story("Car", "<RoutingAction><RandomRouteAction/></RoutingAction>", go, "R"),
            stop,
            road=SHARED / "ncap" / "OpenDRIVE" / "NCAP" / "X-Intersection_NCAP.xodr",
        ),
        "nurbs_trajectory.xosc": scenario_xml(
            cars,
            teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -4, 50, 10),
            story("Car", NURBS_FOLLOW, go, "N"),
            f"<ConditionGroup>{action_state('NAction', 'completeState')}</ConditionGroup>",
        ),
        "geo_position.xosc": scenario_xml(
            cars,
            teleport_speed("Ego", -5, 20, 10) + GEO_INIT,
            story("Car", GEO_ACQUIRE, go, "G"),
            f"<ConditionGroup>{GEO_REACHED}</ConditionGroup>",
            road=write(folder / "geo_straight.xodr", geo_straight()),
        ),
        "variables.xosc": scenario_xml(
            cars,
            teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -4, 50, 10),
            _variable_story(),
            VARIABLES_DONE,
            params='<ParameterDeclaration name="Gain" parameterType="double" value="1"/>',
            variables=VARIABLES,
        ),
        "clothoid_trajectory.xosc": scenario_xml(
            {"Ego": "", "Car": "", "Van": ""},
            teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -4, 50, 10)
            + teleport_speed("Van", -3, 80, 10),
            story("Car", CLOTHOID_FOLLOW, go, "C") + story("Van", POLYLINE_FOLLOW, go, "L"),
            stop,
        ),
        "synchronize.xosc": scenario_xml(
            cars,
            teleport_speed("Ego", -4, 50, 10) + teleport_speed("Car", -3, 100, 0),
            story("Car", SYNCHRONIZE, go, "Y"),
            stop,
        ),
        "global_actions.xosc": scenario_xml(
            {"Ego": "", "Car": "", "Van": ""},
            FOG_INIT + teleport_speed("Ego", -5, 20, 10) + teleport_speed("Car", -4, 50, 10)
            + teleport_speed("Van", -3, 120, 10),
            global_story("Del", '<EntityAction entityRef="Car"><DeleteEntityAction/></EntityAction>', 0.5)
            + global_story("Add", ADD_CAR, 1.5) + global_story("Sw", SWARM, 0.5)
            + global_story("Src", SOURCE, 0.5) + global_story("Snk", SINK, 0.5)
            + global_story("Off", '<TrafficAction trafficName="src"><TrafficStopAction/></TrafficAction>', 2.5),
            stop,
        ),
    }  # fmt: skip
    return [write(folder / name, text) for name, text in texts.items()]


def global_story(name: str, action: str, t: float) -> str:
    """One story running the GlobalAction body ``action`` once at ``t`` s."""
    return f"""<Story name="{name}S"><Act name="{name}A"><ManeuverGroup maximumExecutionCount="1" name="{name}G">
<Actors selectTriggeringEntities="false"/><Maneuver name="{name}M"><Event name="{name}" priority="override">
<Action name="{name}Action"><GlobalAction>{action}</GlobalAction></Action>
<StartTrigger><ConditionGroup>{time_condition(t, name + "t", "none")}</ConditionGroup></StartTrigger></Event></Maneuver></ManeuverGroup>
<StartTrigger><ConditionGroup>{time_condition(0, name + "g", "none")}</ConditionGroup></StartTrigger></Act></Story>"""


#: A clothoid from the car's start in lane -4 (y = -8), curvature 0 to 0.002 1/m over 100 m.
CLOTHOID_FOLLOW = """<RoutingAction><FollowTrajectoryAction><TimeReference><None/></TimeReference>
<TrajectoryFollowingMode followingMode="position"/><TrajectoryRef><Trajectory name="bend" closed="false"><Shape>
<Clothoid curvature="0" curvaturePrime="0.00002" length="100"><Position><WorldPosition x="55" y="-8" h="0"/></Position></Clothoid>
</Shape></Trajectory></TrajectoryRef></FollowTrajectoryAction></RoutingAction>"""
#: A polyline from lane -3 (y = -4.5) into lane -4 over 40 m, untimed.
POLYLINE_FOLLOW = """<RoutingAction><FollowTrajectoryAction><TimeReference><None/></TimeReference>
<TrajectoryFollowingMode followingMode="position"/><TrajectoryRef><Trajectory name="drift" closed="false"><Shape><Polyline>
<Vertex><Position><WorldPosition x="85" y="-4.5" h="0"/></Position></Vertex>
<Vertex><Position><WorldPosition x="125" y="-8"/></Position></Vertex>
<Vertex><Position><WorldPosition x="200" y="-8"/></Position></Vertex></Polyline>
</Shape></Trajectory></TrajectoryRef></FollowTrajectoryAction></RoutingAction>"""
#: The actor (at rest at s = 100) reaches s = 250 in lane -3 when the ego (10 m/s from
#: s = 50) reaches s = 150, at 12 m/s over the last 30 m.
SYNCHRONIZE = """<SynchronizeAction masterEntityRef="Ego">
<TargetPositionMaster><LanePosition roadId="0" laneId="-4" s="150"/></TargetPositionMaster>
<TargetPosition><LanePosition roadId="0" laneId="-3" s="250"/></TargetPosition>
<FinalSpeed><AbsoluteSpeed value="12"><TargetDistanceSteadyState distance="30"/></AbsoluteSpeed></FinalSpeed>
</SynchronizeAction>"""
FOG_INIT = """<GlobalAction><EnvironmentAction><Environment name="Fog"><TimeOfDay animation="false" dateTime="2026-06-01T21:30:00"/>
<Weather fractionalCloudCover="eightOktas"><Sun illuminance="10" azimuth="0" elevation="0.1"/><Fog visualRange="80"/>
<Precipitation precipitationType="rain" precipitationIntensity="5"/></Weather>
<RoadCondition frictionScaleFactor="0.7"/></Environment></EnvironmentAction></GlobalAction>"""
ADD_CAR = """<EntityAction entityRef="Car"><AddEntityAction><Position>
<LanePosition roadId="0" laneId="-4" s="200"/></Position></AddEntityAction></EntityAction>"""
SWARM = """<TrafficAction trafficName="sw"><TrafficSwarmAction innerRadius="15" numberOfVehicles="3" offset="20"
semiMajorAxis="120" semiMinorAxis="15"><CentralObject entityRef="Ego"/><InitialSpeedRange lowerLimit="8" upperLimit="12"/>
<DirectionOfTravelDistribution same="1" opposite="0"/></TrafficSwarmAction></TrafficAction>"""
SOURCE = """<TrafficAction trafficName="src"><TrafficSourceAction radius="0" rate="2" speed="20">
<Position><LanePosition roadId="0" laneId="-1" s="100"/></Position></TrafficSourceAction></TrafficAction>"""
SINK = """<TrafficAction trafficName="snk"><TrafficSinkAction radius="15">
<Position><LanePosition roadId="0" laneId="-1" s="150"/></Position></TrafficSinkAction></TrafficAction>"""


def action_state(action: str, state: str) -> str:
    """A StoryboardElementStateCondition on action ``action`` reaching ``state``."""
    return f"""<Condition name="{action}{state}" delay="0" conditionEdge="none"><ByValueCondition>
<StoryboardElementStateCondition storyboardElementType="action" storyboardElementRef="{action}" state="{state}"/>
</ByValueCondition></Condition>"""


#: A quadratic NURBS (order 3: four control points, 4 + 3 clamped knots) from lane -4 into
#: lane -3 of the straight road (its centres at y = -8 and -4.5), 60 m long, timed relative
#: to the action's start (control point times 0 .. 6 s), followed by position.
NURBS_FOLLOW = """<RoutingAction><FollowTrajectoryAction initialDistanceOffset="0">
<TrajectoryRef><Trajectory name="Swerve" closed="false"><Shape><Nurbs order="3">
<ControlPoint time="0" weight="1"><Position><WorldPosition x="55" y="-8" h="0"/></Position></ControlPoint>
<ControlPoint time="2"><Position><WorldPosition x="75" y="-8"/></Position></ControlPoint>
<ControlPoint time="4" weight="2"><Position><WorldPosition x="95" y="-4.5"/></Position></ControlPoint>
<ControlPoint time="6"><Position><WorldPosition x="115" y="-4.5"/></Position></ControlPoint>
<Knot value="0"/><Knot value="0"/><Knot value="0"/><Knot value="1"/><Knot value="2"/><Knot value="2"/><Knot value="2"/>
</Nurbs></Shape></Trajectory></TrajectoryRef>
<TimeReference><Timing domainAbsoluteRelative="relative" scale="1" offset="0"/></TimeReference>
<TrajectoryFollowingMode followingMode="position"/>
</FollowTrajectoryAction></RoutingAction>"""

#: Transverse Mercator about 48 N 11 E, the map's origin 100 m west and 5 m north of the
#: projection's (OpenDRIVE header offset).
GEO_PROJ = "+proj=tmerc +lat_0=48 +lon_0=11 +k=1 +x_0=0 +y_0=0 +ellps=WGS84"


def geo_straight() -> str:
    """The ALKS straight road with a geoReference (GEO_PROJ) and a header offset."""
    header = (
        f'<geoReference><![CDATA[{GEO_PROJ}]]></geoReference><offset x="-100" y="5" z="0" hdg="0"/>'
    )
    return STRAIGHT.read_text().replace("</header>", header + "</header>", 1)


#: The car placed by latitude and longitude at map (60, -8), lane -4, heading east; 10 m/s.
GEO_INIT = """<Private entityRef="Car">
<PrivateAction><TeleportAction><Position><GeoPosition latitudeDeg="47.999973018" longitudeDeg="10.999463989" altitude="0" verticalRoadSelection="0">
<Orientation type="absolute" h="0" p="0" r="0"/></GeoPosition></Position></TeleportAction></PrivateAction>
<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="10"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>
</Private>"""
#: Map (200, -8), 140 m down lane -4 from the car's start.
GEO_TARGET = '<GeoPosition latitudeDeg="47.999973011" longitudeDeg="11.001340026"/>'
GEO_ACQUIRE = (
    f"<RoutingAction><AcquirePositionAction><Position>{GEO_TARGET}</Position>"
    "</AcquirePositionAction></RoutingAction>"
)
#: The car within 97.75 m (along the road, reference points) of GEO_TARGET: at x > 102.25 m,
#: after 4.225 s.
GEO_REACHED = f"""<Condition name="near" delay="0" conditionEdge="rising"><ByEntityCondition>
<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Car"/></TriggeringEntities>
<EntityCondition><DistanceCondition value="97.75" freespace="false" rule="lessThan" coordinateSystem="road"
relativeDistanceType="longitudinal"><Position>{GEO_TARGET}</Position></DistanceCondition></EntityCondition>
</ByEntityCondition></Condition>"""

#: One variable of each kind the seeds change.
VARIABLES = """<VariableDeclaration name="Armed" variableType="boolean" value="false"/>
<VariableDeclaration name="Count" variableType="double" value="0"/>
<VariableDeclaration name="Label" variableType="string" value="idle"/>"""


def _value_condition(name: str, ref: str, rule: str, value: str, tag: str = "Variable") -> str:
    """A Variable- (or Parameter-) Condition named ``name`` on ``ref``."""
    attr = "variableRef" if tag == "Variable" else "parameterRef"
    return f"""<Condition name="{name}" delay="0" conditionEdge="none"><ByValueCondition>
<{tag}Condition {attr}="{ref}" rule="{rule}" value="{value}"/></ByValueCondition></Condition>"""


def _event(name: str, actions: str, condition: str, count: int = 1) -> str:
    return f"""<Event name="{name}" priority="parallel" maximumExecutionCount="{count}">{actions}
<StartTrigger><ConditionGroup>{condition}</ConditionGroup></StartTrigger></Event>"""


def _variable_action(ref: str, body: str, tag: str = "Variable") -> str:
    attr = "variableRef" if tag == "Variable" else "parameterRef"
    return f'<GlobalAction><{tag}Action {attr}="{ref}">{body}</{tag}Action></GlobalAction>'


def _modify(rule: str, value: str) -> str:
    return f'<ModifyAction><Rule><{rule} value="{value}"/></Rule></ModifyAction>'


SLOW = """<PrivateAction><LongitudinalAction><SpeedAction>
<SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="rate" value="4"/>
<SpeedActionTarget><AbsoluteTargetSpeed value="6"/></SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>"""


def _action(name: str, body: str) -> str:
    return f'<Action name="{name}">{body}</Action>'


def _set(value: str) -> str:
    return f'<SetAction value="{value}"/>'


def _variable_story() -> str:
    """At 0.5 s Armed := true and Label := armed; while Armed, Count += 1 (three executions);
    when Count >= 3: Count *= 2, the car slows to 6 m/s, and the deprecated ParameterAction
    sets Gain := 2 and multiplies it by 1.5 (two actions of one event, in document order)."""
    arm = _action("SetArmed", _variable_action("Armed", _set("true")))
    arm += _action("SetLabel", _variable_action("Label", _set("armed")))
    tick = _action("AddOne", _variable_action("Count", _modify("AddValue", "1")))
    double = _action("Times2", _variable_action("Count", _modify("MultiplyByValue", "2")))
    double += _action("Slow", SLOW)
    double += _action("SetGain", _variable_action("Gain", _set("2"), "Parameter"))
    scale = _modify("MultiplyByValue", "1.5")
    double += _action("ScaleGain", _variable_action("Gain", scale, "Parameter"))
    events = _event("Arm", arm, time_condition(0.5, "arm", "none"))
    events += _event("Tick", tick, _value_condition("armed", "Armed", "equalTo", "true"), 3)
    events += _event("Double", double, _value_condition("three", "Count", "greaterOrEqual", "3"))
    return f"""<Story name="V"><Act name="VAct"><ManeuverGroup maximumExecutionCount="1" name="VG">
<Actors selectTriggeringEntities="false"><EntityRef entityRef="Car"/></Actors><Maneuver name="VM">{events}
</Maneuver></ManeuverGroup>
<StartTrigger><ConditionGroup>{time_condition(0, "Vstart", "none")}</ConditionGroup></StartTrigger></Act></Story>"""


#: Stops once every change is seen: Count = 6, Label = armed, Gain = 3 (a ParameterCondition).
VARIABLES_DONE = (
    f"<ConditionGroup>{_value_condition('six', 'Count', 'equalTo', '6')}"
    f"{_value_condition('labelled', 'Label', 'equalTo', 'armed')}"
    f"{_value_condition('gain', 'Gain', 'equalTo', '3', 'Parameter')}</ConditionGroup>"
)
