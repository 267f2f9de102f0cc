"""The quiet step (snapshot, triggers, motion and commands in one compiled call) against the
general path, on real SUMO: the same scenario run with quiet steps and with every step on
the general path gives bit-identical actor tables, reports and SUMO states at every step, and
the quiet path is taken, including its fired, ended and complete outcomes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from paths import REPO_ROOT

from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.engine import executor as executor_module
from hiyari.bridge.openscenario.model import (
    AbsoluteLane,
    AbsoluteSpeed,
    Act,
    Action,
    Condition,
    ControllerSpec,
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
    TimeToCollisionCondition,
    TransitionDynamics,
)
from hiyari.bridge.openscenario.model.actions import RelativeSpeed
from hiyari.checkout import shared_dir
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.simulation import SimConfig, Simulation

XODR = shared_dir(REPO_ROOT) / "data/openscenario/alks/road_networks/alks_road_straight.xodr"
DT, STEPS, N = 0.05, 240, 6


def _car(name: str, controller: ControllerSpec | None = None) -> Entity:
    return Entity(
        name, EntityKind.VEHICLE, ActorClass.CAR, 5.0, 2.0, 1.8, (1.4, 0.0, 0.9),
        controller=controller,
    )  # fmt: skip


def _scenario() -> Scenario:
    """Cars on three lanes: each changes lane at its time (lateral transitions that end),
    slows by rate whenever close to the next car (speed transitions that end, and events
    firing again and again), but car1, which follows car0's speed continuously while car0
    brakes (a goal read from another entity every step)."""
    names = [f"car{k}" for k in range(N)]
    step = TransitionDynamics(Shape.STEP, Dimension.TIME, 0.0)
    ents = [_car("Ego", ControllerSpec("x"))] + [_car(n) for n in names]
    init = [
        InitAction("Ego", Action("ego_pos", TeleportAction(LanePosition("0", -4, 5.0)))),
        InitAction("Ego", Action("ego_v", SpeedAction(step, AbsoluteSpeed(20.0)))),
    ]
    lanes = (-3, -4, -5, -3, -4, -5)
    groups = []
    for k, n in enumerate(names):
        s = 60.0 + 25.0 * k
        init.append(
            InitAction(n, Action(f"{n}_pos", TeleportAction(LanePosition("0", lanes[k], s))))
        )
        init.append(InitAction(n, Action(f"{n}_v", SpeedAction(step, AbsoluteSpeed(12.0 + k)))))
        other = names[(k + 1) % N]
        lc = LaneChangeAction(
            TransitionDynamics(Shape.SINUSOIDAL, Dimension.TIME, 2.0),
            AbsoluteLane(-4 if lanes[k] != -4 else -3),
        )
        slow = SpeedAction(
            TransitionDynamics(Shape.LINEAR, Dimension.RATE, 3.0), AbsoluteSpeed(8.0)
        )
        near = Condition(
            f"{n}_near",
            EntityCondition(
                (n,), "any",
                RelativeDistanceCondition(other, DistanceType.LONGITUDINAL, 15.0, True, Rule.LESS_THAN),
            ),
            Edge.RISING,
        )  # fmt: skip
        ttc = Condition(
            f"{n}_ttc",
            EntityCondition(
                (n,), "any", TimeToCollisionCondition(2.5, True, Rule.LESS_THAN, entity="Ego")
            ),
            Edge.RISING,
        )
        at = Condition(
            f"{n}_t", SimulationTimeCondition(1.0 + 0.7 * k, Rule.GREATER_OR_EQUAL), Edge.RISING
        )
        events = [Event(f"{n}_lc", (Action(f"{n}_lca", lc),), ((at,),))]
        if k != 1:
            events.append(
                Event(f"{n}_slow", (Action(f"{n}_sa", slow),), ((near,), (ttc,)), "parallel", 1000)
            )
        else:
            follow = SpeedAction(
                TransitionDynamics(Shape.LINEAR, Dimension.TIME, 1.5),
                RelativeSpeed("car0", 0.5, continuous=True),
            )
            late = Condition(
                "follow_t", SimulationTimeCondition(7.0, Rule.GREATER_OR_EQUAL), Edge.RISING
            )
            events.append(Event("follow", (Action("follow_a", follow),), ((late,),)))
        if k == 0:  # car0 brakes while car1 follows its speed
            brake = SpeedAction(
                TransitionDynamics(Shape.LINEAR, Dimension.RATE, 1.0), AbsoluteSpeed(4.0)
            )
            later = Condition(
                "brake_t", SimulationTimeCondition(8.0, Rule.GREATER_OR_EQUAL), Edge.RISING
            )
            events.append(Event("brake", (Action("brake_a", brake),), ((later,),)))
        groups.append(ManeuverGroup(f"{n}_g", (n,), (Maneuver(f"{n}_m", tuple(events)),)))
    stop = ((Condition("end", SimulationTimeCondition(1e6, Rule.GREATER_OR_EQUAL), Edge.RISING),),)
    story = Story("s", (Act("a", tuple(groups)),))
    return Scenario("quiet", tuple(ents), Storyboard(tuple(init), (story,), stop), ego="Ego")


def _run(net: Path, roads: RoadLanes, quiet: bool) -> list[tuple]:
    """Per step: the engine's actor table, its report and SUMO's positions after the step."""
    out = []
    with Simulation(SimConfig(net=net, step_length=DT)) as sim:
        engine = ScenarioEngine(_scenario(), roads, DT)
        if not quiet:
            engine._quiet_args = lambda: None  # every step on the general path
        engine.start(sim)
        for _ in range(STEPS):
            world = sim.step()
            report = engine.step(sim, world)
            sim.set_speed("Ego", 20.0)
            out.append((engine.table.state.copy(), report, world.ids.tolist(), world.xyz.copy()))
    return out


@pytest.fixture(scope="module")
def roads(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, RoadLanes]:
    net = import_opendrive(XODR, tmp_path_factory.mktemp("net") / "straight.net.xml")
    return net, RoadLanes.from_files(XODR, net)


def test_quiet_steps_equal_the_general_path_bit_for_bit(
    roads: tuple[Path, RoadLanes], monkeypatch: pytest.MonkeyPatch
) -> None:
    net, lanes = roads
    outcomes = {"fired": 0, "ended": 0, "complete": 0}
    kernel = executor_module.quiet_step

    def counted(*args: object) -> tuple:
        res = kernel(*args)
        n_fired, ended, _, _, placed, _ = res
        key = "fired" if n_fired else ("ended" if ended or not placed else "complete")
        outcomes[key] += 1
        return res

    monkeypatch.setattr(executor_module, "quiet_step", counted)
    fast = _run(net, lanes, quiet=True)
    assert outcomes["complete"] > STEPS // 2  # most steps are quiet
    assert outcomes["fired"] > 0 and outcomes["ended"] > 0
    monkeypatch.setattr(executor_module, "quiet_step", kernel)
    general = _run(net, lanes, quiet=False)
    for k, (a, b) in enumerate(zip(fast, general, strict=True)):
        assert np.array_equal(a[0], b[0], equal_nan=True), f"actor table differs at step {k}"
        assert a[1] == b[1], f"report differs at step {k}"
        assert a[2] == b[2] and np.array_equal(a[3], b[3]), f"SUMO state differs at step {k}"
    started = {a for r in fast for a in r[1].started}
    ended = {a for r in fast for a in r[1].ended}
    lane_changes = {f"car{k}_lca" for k in range(N)}
    assert lane_changes | {"follow_a", "brake_a"} <= started and lane_changes <= ended
    assert any(a.endswith("_sa") for a in started & ended)  # a slow-down ran to its end
