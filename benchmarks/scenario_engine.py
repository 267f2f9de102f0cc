"""Cost of the storyboard engine per step against the SUMO step it drives.

A scenario of 50 scripted vehicles on the ALKS straight road (three lanes each way) with 200
trigger conditions (relative distance, TTC, headway, speed, simulation time, element state)
whose events start lane changes and speed changes. Per step we time, in the same run:
SUMO's step (simulationStep + WorldState read + contact check) plus the time libsumo itself
spends in the engine's commands (moveToXY and setSpeed per scripted actor: the unavoidable
cost of moving them), and the engine's own work (trigger evaluation, storyboard update,
kinematics, and the Python side of its commands). Prints both and their ratio (the issue's target: the engine <= 10 %).
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from hiyari.bridge.scenario.engine import ScenarioEngine
from hiyari.bridge.scenario.model import (
    AbsoluteLane,
    AbsoluteSpeed,
    Act,
    Action,
    Condition,
    ControllerSpec,
    CoordinateSystem,
    Dimension,
    DistanceType,
    Edge,
    Entity,
    EntityCondition,
    EntityKind,
    Event,
    InitAction,
    LaneChangeAction,
    LanePosition,
    Maneuver,
    ManeuverGroup,
    RelativeDistanceCondition,
    Rule,
    Scenario,
    Shape,
    SimulationTimeCondition,
    SpeedAction,
    Story,
    Storyboard,
    TeleportAction,
    TimeHeadwayCondition,
    TimeToCollisionCondition,
    TransitionDynamics,
)
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.simulation import SimConfig, Simulation

XODR = (
    Path(__file__).resolve().parents[2]
    / "shared/data/openscenario/alks/road_networks/alks_road_straight.xodr"
)
N_ACTORS, STEPS, DT = 50, 600, 0.05
LANES = (-3, -4, -5, 3, 4, 5)


def _car(name: str) -> Entity:
    return Entity(name, EntityKind.VEHICLE, ActorClass.CAR, 5.0, 2.0, 1.8, (1.4, 0.0, 0.9))


def _scenario() -> Scenario:
    names = [f"car{k}" for k in range(N_ACTORS)]
    ents = [
        Entity(
            "Ego",
            EntityKind.VEHICLE,
            ActorClass.CAR,
            5.0,
            2.0,
            1.8,
            (1.4, 0.0, 0.9),
            controller=ControllerSpec("x"),
        )
    ]
    ents += [_car(n) for n in names]
    step = TransitionDynamics(Shape.STEP, Dimension.TIME, 0.0)
    init = [
        InitAction("Ego", Action("ego_pos", TeleportAction(LanePosition("0", -4, 5.0)))),
        InitAction("Ego", Action("ego_v", SpeedAction(step, AbsoluteSpeed(20.0)))),
    ]
    for k, n in enumerate(names):
        lane = LANES[k % len(LANES)]
        s = 100.0 + 40.0 * (k // len(LANES)) if lane < 0 else 4000.0 - 40.0 * (k // len(LANES))
        init.append(InitAction(n, Action(f"{n}_pos", TeleportAction(LanePosition("0", lane, s)))))
        init.append(InitAction(n, Action(f"{n}_v", SpeedAction(step, AbsoluteSpeed(15.0 + k % 7)))))
    groups = []
    for k, n in enumerate(names):
        lane = LANES[k % len(LANES)]
        other = names[(k + 1) % N_ACTORS]
        target = lane + (1 if lane in (-5, -4, 3, 4) else -1)
        lc = LaneChangeAction(
            TransitionDynamics(Shape.SINUSOIDAL, Dimension.TIME, 4.0), AbsoluteLane(target)
        )
        slow = SpeedAction(
            TransitionDynamics(Shape.LINEAR, Dimension.RATE, 2.0), AbsoluteSpeed(10.0)
        )

        def cond(name: str, body: object, trig: tuple[str, ...] = (n,)) -> Condition:
            return Condition(name, EntityCondition(trig, "any", body), Edge.RISING)

        c = [
            cond(
                f"{n}d",
                RelativeDistanceCondition(
                    other, DistanceType.LONGITUDINAL, 20.0, True, Rule.LESS_THAN
                ),
            ),
            cond(f"{n}t", TimeToCollisionCondition(3.0, True, Rule.LESS_THAN, entity="Ego")),
            cond(
                f"{n}h",
                TimeHeadwayCondition(other, 1.0, True, Rule.LESS_THAN, CoordinateSystem.ROAD),
            ),
        ]
        t = Condition(
            f"{n}time", SimulationTimeCondition(2.0 + 0.2 * k, Rule.GREATER_OR_EQUAL), Edge.RISING
        )
        # e1: a lane change at its time; e2: slow down whenever too close (runs again and
        # again, so its 3 entity conditions are evaluated every step)
        events = (
            Event(f"{n}_e1", (Action(f"{n}_lc", lc),), ((t,),)),
            Event(
                f"{n}_e2", (Action(f"{n}_slow", slow),), ((c[0], c[1]), (c[2],)), "parallel", 10_000
            ),
        )
        groups.append(ManeuverGroup(f"{n}_g", (n,), (Maneuver(f"{n}_m", events),)))
    story = Story("bench", (Act("act", tuple(groups)),))
    stop = ((Condition("end", SimulationTimeCondition(1e6, Rule.GREATER_OR_EQUAL), Edge.RISING),),)
    return Scenario("bench", tuple(ents), Storyboard(tuple(init), (story,), stop), ego="Ego")


def main() -> None:
    sc = _scenario()
    n_cond = sum(len(g) for trig in _triggers(sc) for g in trig)
    with tempfile.TemporaryDirectory() as tmp:
        net = import_opendrive(XODR, Path(tmp) / "straight.net.xml")
        roads = RoadLanes.from_files(XODR, net)
        with Simulation(SimConfig(net=net, step_length=DT)) as sim:
            engine = ScenarioEngine(sc, roads, DT)
            commands = [0.0]
            vehicle = sim._api().vehicle  # time libsumo's own moveToXY / setSpeed work

            def timed(fn: Callable[..., None]) -> Callable[..., None]:
                def call(*args: object, **kw: object) -> None:
                    t = time.perf_counter()
                    fn(*args, **kw)
                    commands[0] += time.perf_counter() - t

                return call

            vehicle.moveToXY = timed(vehicle.moveToXY)
            vehicle.setSpeed = timed(vehicle.setSpeed)
            engine.start(sim)
            t_sumo = t_engine = 0.0
            started = 0
            for _ in range(STEPS):
                t = time.perf_counter()
                world = sim.step()
                t_sumo += time.perf_counter() - t
                commands[0] = 0.0
                t = time.perf_counter()
                report = engine.step(sim, world)
                t_engine += time.perf_counter() - t - commands[0]
                t_sumo += commands[0]
                started += len(report.started)
                sim.set_speed("Ego", 20.0)
    sumo_ms, eng_ms = 1e3 * t_sumo / STEPS, 1e3 * t_engine / STEPS
    print(
        f"scenario: {N_ACTORS} scripted actors, {n_cond} conditions, {STEPS} steps, {started} actions started"
    )
    print(
        f"SUMO step (simulationStep + WorldState + contacts + libsumo moveToXY/setSpeed): {sumo_ms:.3f} ms/step"
    )
    print(f"storyboard engine (triggers + storyboard + kinematics):        {eng_ms:.3f} ms/step")
    print(f"ratio engine / SUMO step: {eng_ms / sumo_ms:.3f} (target <= 0.10)")


def _triggers(sc: Scenario) -> list:
    out = [sc.storyboard.stop_trigger]
    for story in sc.storyboard.stories:
        for act in story.acts:
            out += [act.start_trigger]
            out += [ev.start_trigger for g in act.groups for m in g.maneuvers for ev in m.events]
    return out


if __name__ == "__main__":
    main()
