"""Cost of the storyboard engine per step against the SUMO step it drives.

A scenario of 50 scripted vehicles on the ALKS straight road (three lanes each way) with 200
trigger conditions (relative distance, TTC, headway, speed, simulation time, element state)
whose events start lane changes and speed changes. Per step we time, interleaved in the same
run: SUMO's step (simulationStep + WorldState read + contact check) plus the time libsumo itself
spends in the engine's commands (moveToXY and setSpeed per scripted actor: the unavoidable cost
of moving them), and the engine's own work (trigger evaluation, storyboard update, kinematics,
and the Python side of its commands). The engine's commands reach libsumo's SWIG functions
(``_libsumo.vehicle_moveToXY`` / ``vehicle_setSpeed``) in two C-level loops per step
(``deque(map(...))`` in ``traffic.commands``); the benchmark times those two loops as libsumo's
share by timing ``traffic.commands``' ``deque`` for one run at a time (put back after each
run): no Python runs between the calls, so the measurement adds two clock reads per loop and
nothing per call (a per-call wrapper, used before, ran Python after every libsumo call, in
caches SUMO had just evicted: it cost the engine side 30-50 us a step in place, several times
its cost measured on a no-op). The loops' own C iteration (about 40 ns a call) falls on
libsumo's side. The wrapper's cost outside its window (measured on a no-op in the same process,
times the calls counted) is printed. Prints the medians over all steps of all repeats, their
ratio (the issue's target: the engine <= 10 % of the SUMO step) and the load average.

To say where the floor of a numpy design lies it also runs the same scenario with 5 actors (the
engine's fixed cost per step) and times one small numpy call in the same process: the engine's
time divided by that is its cost in numpy-call equivalents, against what the target allows. A short warm-up run
first compiles the engine's numba kernels (or loads them from numba's cache), outside the timing.

    .venv/bin/python benchmarks/scenario_engine.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path

import numpy as np

from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.model import (
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
from hiyari.checkout import shared_dir
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.traffic import commands
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.simulation import SimConfig, Simulation

XODR = shared_dir() / "data/openscenario/alks/road_networks/alks_road_straight.xodr"
N_ACTORS, STEPS, DT = 50, 600, 0.05
_DEQUE = deque  # traffic.commands' own, restored after each run
LANES = (-3, -4, -5, 3, 4, 5)


def _car(name: str) -> Entity:
    return Entity(name, EntityKind.VEHICLE, ActorClass.CAR, 5.0, 2.0, 1.8, (1.4, 0.0, 0.9))


def _scenario(n_actors: int) -> Scenario:
    names = [f"car{k}" for k in range(n_actors)]
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
        other = names[(k + 1) % n_actors]
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


def _run(
    sc: Scenario, net: Path, roads: RoadLanes, steps: int = STEPS
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Per-step SUMO and engine times (s) and wrapped libsumo calls of ``steps`` steps of
    ``sc``, and the actions started."""
    with Simulation(SimConfig(net=net, step_length=DT)) as sim:
        engine = ScenarioEngine(sc, roads, DT)
        # time libsumo's own moveToXY / setSpeed loops: traffic.commands drives the SWIG
        # functions by deque(map(...)), so its ``deque`` is timed. The module is shared by
        # every run in this process: the original is put back after the run, else each run
        # would wrap the previous run's wrapper (whose cost then lands inside the window)
        windows: list[float] = []
        commands.deque = _timed(_DEQUE, windows)
        try:
            engine.start(sim)
            t_sumo, t_engine, calls = np.zeros(steps), np.zeros(steps), np.zeros(steps)
            started = 0
            for k in range(steps):
                t = time.perf_counter()
                world = sim.step()
                t_sumo[k] = time.perf_counter() - t
                windows.clear()
                t = time.perf_counter()
                report = engine.step(sim, world)
                t_engine[k] = time.perf_counter() - t
                spent = math.fsum(windows)
                t_engine[k] -= spent
                t_sumo[k] += spent
                calls[k] = len(windows)
                started += len(report.started)
                sim.set_speed("Ego", 20.0)
        finally:
            commands.deque = _DEQUE
    return t_sumo, t_engine, calls, started


def _timed(fn: Callable[..., object], windows: list[float]) -> Callable[..., None]:
    """``fn`` (``deque``, consuming a loop of libsumo calls) appending the time it took (s)
    to ``windows``; kept lean, as its cost outside the window lands on the engine's side."""
    clock, add = time.perf_counter, windows.append

    def call(*args: object, **kwargs: object) -> None:
        t = clock()
        fn(*args, **kwargs)
        add(clock() - t)

    return call


def _call_cost() -> float:
    """Median time (s) of one small numpy call (adding two 150-element arrays)."""
    a, b = np.ones(150), np.ones(150)
    runs = []
    for _ in range(50):
        t = time.perf_counter()
        for _ in range(200):
            np.add(a, b)
        runs.append((time.perf_counter() - t) / 200)
    return float(np.median(runs))


def _wrapper_cost() -> float:
    """Time (s) per timed loop that the timing wrapper adds outside its own window (so on
    the engine's side): the call into the wrapper, a clock read and the append, measured on
    an empty loop."""
    windows: list[float] = []
    call, n = _timed(_DEQUE, windows), 500
    runs = []
    for _ in range(20):
        windows.clear()
        t = time.perf_counter()
        for _ in range(n):
            call((), maxlen=0)
        runs.append((time.perf_counter() - t - math.fsum(windows)) / n)
    return max(0.0, float(np.median(runs)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs of the 50-actor scenario")
    args = parser.parse_args()
    sc, small = _scenario(N_ACTORS), _scenario(5)
    n_cond = sum(len(g) for trig in _triggers(sc) for g in trig)
    n_small = sum(len(g) for trig in _triggers(small) for g in trig)
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        net = import_opendrive(XODR, Path(tmp) / "straight.net.xml")
        roads = RoadLanes.from_files(XODR, net)
        t = time.perf_counter()
        _run(small, net, roads, 60)  # the engine's kernels compile (or load) outside the timing
        warm_s = time.perf_counter() - t
        sumo, eng, ratios, calls = [], [], [], []
        for _ in range(args.repeats):
            t_sumo, t_engine, n_calls, started = _run(sc, net, roads)
            sumo.append(t_sumo)
            eng.append(t_engine)
            calls.append(n_calls)
            ratios.append(np.median(t_engine) / np.median(t_sumo))
        s_sumo, s_eng, _, _ = _run(small, net, roads)
    sumo_ms, eng_ms = 1e3 * np.median(np.concatenate(sumo)), 1e3 * np.median(np.concatenate(eng))
    call_us, wrap_us = 1e6 * _call_cost(), 1e6 * _wrapper_cost()
    print(f"load average (1 min): {load0:.2f} at start, {os.getloadavg()[0]:.2f} at end (2 cores)")
    print(f"warm-up run (numba kernels compiled, or loaded from their cache): {warm_s:.1f} s")
    print(
        f"scenario: {N_ACTORS} scripted actors, {n_cond} conditions, {STEPS} steps x "
        f"{args.repeats} runs, {started} actions started per run"
    )
    print(
        f"SUMO step (simulationStep + WorldState + contacts + libsumo moveToXY/setSpeed): "
        f"{sumo_ms:.3f} ms/step (median)"
    )
    print(f"storyboard engine (triggers + storyboard + kinematics + command assembly): "
          f"{eng_ms:.3f} ms/step (median)")  # fmt: skip
    print(
        f"ratio engine / SUMO step: {float(np.median(ratios)):.3f} (median of runs: "
        f"{', '.join(f'{r:.3f}' for r in ratios)}; target <= 0.10)"
    )
    n_wrapped = float(np.mean(np.concatenate(calls)))
    wrap_ms = n_wrapped * wrap_us / 1e3
    # as the headline ratio: per run (engine and SUMO timed in the same run), then the median
    bare = [(np.median(e) - 1e-3 * wrap_ms) / np.median(s) for e, s in zip(eng, sumo, strict=True)]
    print(
        f"  of the engine's time, the timing wrapper on its {n_wrapped:.1f} libsumo loops per "
        f"step (mean; {wrap_us:.2f} us each outside its window, measured on an empty loop): "
        f"~{wrap_ms:.3f} ms/step; without it the ratio would be ~{float(np.median(bare)):.3f}"
    )
    print(
        f"same scenario with 5 actors, {n_small} conditions: engine "
        f"{1e3 * np.median(s_eng):.3f} ms/step, SUMO {1e3 * np.median(s_sumo):.3f} ms/step"
    )
    print(
        f"one small numpy call: {call_us:.2f} us -> the engine costs "
        f"{1e3 * eng_ms / call_us:.0f} numpy-call equivalents per step; the target allows "
        f"{0.1 * 1e3 * sumo_ms / call_us:.0f}"
    )


def _triggers(sc: Scenario) -> list:
    out = [sc.storyboard.stop_trigger]
    for story in sc.storyboard.stories:
        for act in story.acts:
            out += [act.start_trigger]
            out += [ev.start_trigger for g in act.groups for m in g.maneuvers for ev in m.events]
    return out


if __name__ == "__main__":
    main()
