"""WorldState against SUMO's own getters, both read paths, and bit-for-bit determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiyari.errors import HiyariError
from hiyari.traffic import ActorClass, SimConfig, Simulation


def _config(net, demand, **kw):
    return SimConfig(net=net, routes=[demand], seed=3, **kw)


def test_worldstate_matches_sumo_getters(intersection_net, intersection_demand):
    checked_veh = checked_ped = 0
    with Simulation(_config(intersection_net, intersection_demand)) as sim:
        for state in sim.run(until=120.0):
            if state.time % 10.0 > 1e-6 or len(state) == 0:
                continue
            for k, aid in enumerate(state.ids):
                is_person = state.cls[k] == ActorClass.PEDESTRIAN
                sumo = sim.sumo_reading(aid, is_person)  # SUMO's own per-object getters
                fx, fy, fz = sumo.front
                # SUMO compass angle (deg, clockwise from north) -> radians CCW from east
                h = math.radians(90.0 - sumo.angle)
                assert math.isclose(math.cos(state.heading[k]), math.cos(h), abs_tol=1e-9)
                assert math.isclose(math.sin(state.heading[k]), math.sin(h), abs_tol=1e-9)
                length = sumo.length
                # xyz is the rectangle centre: half a length behind SUMO's front position
                assert state.xyz[k, 0] == pytest.approx(fx - 0.5 * length * math.cos(h), abs=1e-9)
                assert state.xyz[k, 1] == pytest.approx(fy - 0.5 * length * math.sin(h), abs=1e-9)
                assert state.xyz[k, 2] == fz
                assert state.speed[k] == sumo.speed
                assert state.length[k] == length
                assert state.width[k] == sumo.width
                assert state.height[k] == sumo.height
                assert state.lane[k] == sumo.lane
                if state.cls[k] == ActorClass.PEDESTRIAN:
                    checked_ped += 1
                else:
                    assert state.accel[k] == sumo.accel
                    assert state.edge[k] == sumo.edge
                    checked_veh += 1
    assert checked_veh > 50 and checked_ped > 50


def test_vehicle_classes_from_mix(intersection_net, intersection_demand):
    seen = set()
    with Simulation(_config(intersection_net, intersection_demand)) as sim:
        for state in sim.run(until=200.0):
            seen.update(ActorClass(c) for c in state.cls)
    assert {ActorClass.CAR, ActorClass.TRUCK, ActorClass.BUS, ActorClass.PEDESTRIAN} <= seen


def _trace(net, demand, mode, until=90.0):
    with Simulation(_config(net, demand, read_mode=mode)) as sim:
        return list(sim.run(until=until))


def test_same_seed_bit_identical_and_read_paths_agree(intersection_net, intersection_demand):
    a = _trace(intersection_net, intersection_demand, "getters")
    b = _trace(intersection_net, intersection_demand, "getters")
    c = _trace(intersection_net, intersection_demand, "subscriptions")
    assert len(a) == len(b) == len(c) == 900
    assert sum(len(s) for s in a) > 1000
    assert all(x.same_as(y) for x, y in zip(a, b, strict=True))
    # subscriptions deliver the same values (acceleration of persons is differenced the same way)
    assert all(x.same_as(y) for x, y in zip(a, c, strict=True))


def test_different_seed_differs(intersection_net, intersection_demand):
    a = _trace(intersection_net, intersection_demand, "getters", until=60.0)
    with Simulation(SimConfig(net=intersection_net, routes=[intersection_demand], seed=99)) as sim:
        b = list(sim.run(until=60.0))
    assert not all(x.same_as(y) for x, y in zip(a, b, strict=True))


def test_second_simulation_in_process_is_refused(intersection_net, intersection_demand):
    with Simulation(_config(intersection_net, intersection_demand)):
        with pytest.raises(HiyariError, match="one per process"):
            Simulation(_config(intersection_net, intersection_demand)).start()
    # the first one closed cleanly: a new one starts
    with Simulation(_config(intersection_net, intersection_demand)) as sim:
        sim.step()


def test_context_manager_closes_on_error(intersection_net, intersection_demand):
    with pytest.raises(RuntimeError):
        with Simulation(_config(intersection_net, intersection_demand)) as sim:
            sim.step()
            raise RuntimeError("user code failed")
    assert not Simulation.loaded_in_process()


def test_corners_and_velocity_frames():
    from hiyari.traffic import WorldState

    ws = WorldState(
        0.0,
        np.array(["a"], dtype=object),
        np.array([0], np.int8),
        np.array([[10.0, 5.0, 0.0]]),
        np.array([math.pi / 2]),
        np.array([2.0]),
        np.zeros(1),
        np.array([4.0]),
        np.array([2.0]),
        np.array([1.5]),
        np.array(["l_0"], dtype=object),
        np.array(["l"], dtype=object),
    )
    # facing +y: front-left corner is at (x - w/2, y + L/2)
    assert ws.corners()[0, 0] == pytest.approx([9.0, 7.0])
    assert ws.corners()[0, 2] == pytest.approx([11.0, 3.0])
    assert ws.velocity[0] == pytest.approx([0.0, 2.0])


def test_index_and_rows_look_up_ids():
    from hiyari.sensors.scene.synthetic import actor_world

    world = actor_world(
        [
            dict(id="b", cls=ActorClass.CAR, x=0.0, y=0.0),
            dict(id="a", cls=ActorClass.PEDESTRIAN, x=5.0, y=1.0),
            dict(id="c", cls=ActorClass.TRUCK, x=9.0, y=2.0),
        ]
    )
    assert [world.index(i) for i in ("b", "a", "c")] == [0, 1, 2]
    assert world.rows(["c", "nobody", "b"]).tolist() == [2, -1, 0]
    assert world.rows([]).dtype == np.int64 and len(world.rows([])) == 0
    with pytest.raises(KeyError):
        world.index("nobody")
    # the map is per state: a selection looks up its own rows
    sub = world.select(np.array([2, 0]))
    assert sub.index("b") == 1 and sub.rows(["a"]).tolist() == [-1]
