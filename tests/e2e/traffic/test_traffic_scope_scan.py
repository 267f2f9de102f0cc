"""ScopeScan: the scoped state is the full state's rows within the radius whatever the margin
(a cost knob), with actors that jump (moved by commands, parked) and with rare scans."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.traffic import ReadScope, SimConfig, Simulation, WorldState
from hiyari.traffic.read_scope import ScopeScan

RADIUS = 60.0
ROUTE = ["w_in", "e_out"]


def _in_radius(full: WorldState, center: str, radius: float) -> np.ndarray:
    """Rows of ``full`` whose SUMO reference point (front bumper) is within ``radius`` of the
    centre's."""
    d = np.stack([np.cos(full.heading), np.sin(full.heading)], 1)
    front = full.xyz[:, :2] + 0.5 * full.length[:, None] * d
    return np.hypot(*(front - front[full.index(center)]).T) <= radius


def _assert_scoped(state: WorldState, full: WorldState, radius: float) -> None:
    """Every column of ``state`` equals the full state's rows in the radius, bit for bit
    (persons' differenced accelerations aside)."""
    want = full.select(_in_radius(full, "ego", radius))
    assert state.same_as(
        WorldState(**{**want.__dict__, "accel": np.where(want.is_vehicle, want.accel, state.accel)})
    )
    assert np.array_equal(state.accel[state.is_vehicle], want.accel[want.is_vehicle])


def _count_scans(monkeypatch) -> list[int]:
    count = [0]
    scan = ScopeScan._scan

    def counted(self, *args):
        count[0] += 1  # one domain (vehicles or persons) scanned
        return scan(self, *args)

    monkeypatch.setattr(ScopeScan, "_scan", counted)
    return count


@pytest.mark.parametrize("margin", [0.0, 400.0])
def test_any_margin_gives_the_full_state_in_the_radius(
    intersection_net, intersection_demand, monkeypatch, margin
):
    scans = _count_scans(monkeypatch)
    scope = ReadScope("ego", RADIUS, margin=margin)
    cfg = SimConfig(net=intersection_net, routes=[intersection_demand], seed=3, read_scope=scope)
    steps = 0
    with Simulation(cfg) as sim:
        sim.fast_forward(60.0)
        sim.add_vehicle("ego", ROUTE, "DEFAULT_VEHTYPE", "best", 5.0, 8.0, scripted=False)
        while "ego" not in sim.step().ids:
            pass
        scans[0] = 0
        for _ in range(250):
            state = sim.step()
            full = sim.full_state
            if "ego" not in full.ids:
                break
            _assert_scoped(state, full, RADIUS)
            steps += 1
    assert steps > 100
    if margin == 0.0:
        assert scans[0] >= 2 * steps  # nothing can move without closing a zero margin
    else:
        # a margin of a few hundred metres at ~10 m/step of bound: scans every few dozen steps
        assert 0 < scans[0] < steps / 10


def test_actor_moved_by_a_command_is_read_at_once(
    intersection_net, intersection_demand, monkeypatch
):
    scans = _count_scans(monkeypatch)
    scope = ReadScope("ego", 10.0, margin=100.0)
    cfg = SimConfig(net=intersection_net, routes=[intersection_demand], seed=3, read_scope=scope)
    with Simulation(cfg) as sim:
        sim.fast_forward(60.0)
        sim.add_vehicle("ego", ROUTE, "DEFAULT_VEHTYPE", "best", 5.0, 8.0, scripted=False)
        sim.add_vehicle("far", ["s_in", "n_out"], "DEFAULT_VEHTYPE", "best", 1.0, 0.0, True)
        for _ in range(20):
            sim.step()
        full = sim.full_state
        assert "far" in full.ids and "far" not in sim.state.ids
        ego = full.pose_of("ego")
        assert np.hypot(ego.x - full.pose_of("far").x, ego.y - full.pose_of("far").y) > 150.0
        # a jump no speed bound covers: from the far leg to just behind the ego
        back = np.array([np.cos(ego.heading), np.sin(ego.heading)]) * -6.0
        sim.move_vehicle("far", ego.x + back[0], ego.y + back[1], ego.heading, 5.0, speed=0.0)
        before = scans[0]
        state = sim.step()
        assert scans[0] == before  # no scan came by: the command told the scope
        assert "far" in state.ids
        _assert_scoped(state, sim.full_state, 10.0)


def test_parked_vehicle_is_in_scope(intersection_net, intersection_demand):
    import libsumo

    scope = ReadScope("ego", RADIUS, margin=400.0)
    cfg = SimConfig(net=intersection_net, routes=[intersection_demand], seed=3, read_scope=scope)
    parked = 0
    with Simulation(cfg) as sim:
        sim.fast_forward(60.0)
        sim.add_vehicle("parker", ROUTE, "DEFAULT_VEHTYPE", "best", 40.0, 5.0, scripted=False)
        while "parker" not in sim.step().ids:
            pass
        # parking flag (1): SUMO takes it off the lane, where no lane-based search sees it
        libsumo.vehicle.setStop("parker", "w_in", 50.0, 1, 20.0, flags=1)
        sim.add_vehicle("ego", ROUTE, "DEFAULT_VEHTYPE", "best", 5.0, 0.0, scripted=False)
        sim.set_speed("ego", 0.0)
        for _ in range(150):
            state = sim.step()
            full = sim.full_state
            if "ego" not in full.ids:
                continue
            _assert_scoped(state, full, RADIUS)
            if libsumo.vehicle.isStoppedParking("parker"):
                assert "parker" in state.ids
                parked += 1
    assert parked > 50


def test_person_riding_a_bus_is_in_scope(intersection_net, intersection_demand):
    import libsumo

    scope = ReadScope("ego", 100.0, margin=10.0)
    cfg = SimConfig(net=intersection_net, routes=[intersection_demand], seed=3, read_scope=scope)
    riding = outside = 0
    with Simulation(cfg) as sim:
        sim.fast_forward(60.0)
        # the ego waits before the junction on the south arm: the bus passes it
        sim.add_vehicle("ego", ["s_in", "n_out"], "DEFAULT_VEHTYPE", "best", 60.0, 0.0, False)
        sim.set_speed("ego", 0.0)
        # a bus that stops where a person waits for line L1, then carries it away at speed
        libsumo.route.add("r_bus", ROUTE)
        libsumo.vehicle.add("bus", "r_bus", typeID="DEFAULT_VEHTYPE", line="L1", departPos="0")
        libsumo.vehicle.setStop("bus", "w_in", pos=65.0, laneIndex=1, duration=5.0, startPos=50.0)
        libsumo.person.add("rider", "w_in", 58.0)
        libsumo.person.appendDrivingStage("rider", "e_out", lines="L1")
        for _ in range(300):
            state = sim.step()
            full = sim.full_state
            if "ego" not in full.ids:
                continue
            _assert_scoped(state, full, 100.0)
            if "rider" in full.ids and libsumo.person.getVehicle("rider"):
                riding += 1
                outside += "rider" not in state.ids
    assert riding > 10 and 0 < outside < riding
