"""The ego-scoped WorldState (ReadScope) against the full state read in the same step."""

from __future__ import annotations

import numpy as np
import pytest

from hiyari.errors import HiyariError
from hiyari.traffic import ReadScope, SimConfig, Simulation, WorldState

RADIUS = 60.0
ROUTE = ["w_in", "e_out"]
COLUMNS = ("ids", "cls", "xyz", "heading", "speed", "length", "width", "height", "lane", "edge")


def _config(net, demand, scope):
    return SimConfig(net=net, routes=[demand], seed=3, read_scope=scope)


def _front(ws: WorldState) -> np.ndarray:
    """SUMO's reference points: the front-bumper centre (vehicles), the centre (persons)."""
    d = np.stack([np.cos(ws.heading), np.sin(ws.heading)], 1)
    return ws.xyz[:, :2] + 0.5 * ws.length[:, None] * d


def _expected(full: WorldState, center: str, radius: float) -> np.ndarray:
    """Rows of ``full`` within ``radius`` of the centre's front bumper, the centre included."""
    f = _front(full)
    return np.hypot(*(f - f[full.index(center)]).T) <= radius


def test_scope_is_the_full_state_within_the_radius(intersection_net, intersection_demand):
    scope = ReadScope("ego", RADIUS)
    checked = left_out = persons = accel_checked = 0
    with Simulation(_config(intersection_net, intersection_demand, scope)) as sim:
        sim.fast_forward(60.0)
        assert len(sim.state) == len(sim.full_state)  # no ego yet: everyone is read
        sim.add_vehicle("ego", ROUTE, "DEFAULT_VEHTYPE", "best", 5.0, 8.0, scripted=False)
        prev_ids: set[str] = set()
        for _ in range(600):
            state = sim.step()
            full = sim.full_state
            if "ego" not in full.ids:
                if checked:
                    break  # it has arrived
                continue  # not inserted yet
            mask = _expected(full, "ego", RADIUS)
            want = full.select(mask)
            for col in COLUMNS:
                assert np.array_equal(getattr(state, col), getattr(want, col)), col
            veh = state.is_vehicle
            assert np.array_equal(state.accel[veh], want.accel[veh])
            # persons' accelerations are differenced: equal once they were in scope a step ago
            seen = np.array([i in prev_ids for i in state.ids]) & ~veh
            assert np.array_equal(state.accel[seen], want.accel[seen])
            accel_checked += int(seen.sum())
            prev_ids = set(state.ids.tolist())
            checked += 1
            left_out += int((~mask).sum())
            persons += int(state.is_pedestrian.sum())
    assert checked > 100 and left_out > 1000 and persons > 50 and accel_checked > 50


def test_included_actors_are_read_wherever_they_are(intersection_net, intersection_demand):
    with Simulation(_config(intersection_net, intersection_demand, None)) as sim:
        sim.fast_forward(120.0)
        far = sim.state.ids[np.argmax(np.hypot(*(sim.state.xyz[:, :2] - 150.0).T))]
    scope = ReadScope("ego", 10.0, include=(str(far), "not-in-the-network"))
    with Simulation(_config(intersection_net, intersection_demand, scope)) as sim:
        sim.fast_forward(119.9)
        sim.add_vehicle("ego", ROUTE, "DEFAULT_VEHTYPE", "best", 5.0, 8.0, scripted=False)
        state = sim.step()
        full = sim.full_state
        assert "ego" in state.ids and far in state.ids
        want = full.select(_expected(full, "ego", 10.0) | (full.ids == far))
        for col in COLUMNS:
            assert np.array_equal(getattr(state, col), getattr(want, col)), col
        assert len(state) < len(full)


def test_vehicle_and_person_with_one_id_are_both_read(intersection_net, intersection_demand):
    # libsumo files both domains' context results under one key per id: a clash must not mix
    scope = ReadScope("ego", RADIUS)
    with Simulation(_config(intersection_net, intersection_demand, scope)) as sim:
        sim.fast_forward(30.0)
        sim.add_vehicle("ego", ROUTE, "DEFAULT_VEHTYPE", "best", 5.0, 8.0, scripted=False)
        sim.add_vehicle("twin", ROUTE, "DEFAULT_VEHTYPE", "best", 30.0, 8.0, scripted=False)
        sim.add_walking_person("twin", ["w_in", "e_out"], 10.0, "DEFAULT_PEDTYPE")
        for _ in range(50):
            state = sim.step()
            full = sim.full_state
            if list(full.ids).count("twin") == 2 and "ego" in full.ids:
                break
        assert list(state.ids).count("twin") == 2
        want = full.select(_expected(full, "ego", RADIUS))
        for col in COLUMNS:
            assert np.array_equal(getattr(state, col), getattr(want, col)), col


def test_scope_survives_stretches_without_reads(intersection_net, intersection_demand):
    scope = ReadScope("ego", RADIUS)
    with Simulation(_config(intersection_net, intersection_demand, scope)) as sim:
        sim.fast_forward(60.0)
        sim.add_vehicle("ego", ROUTE, "DEFAULT_VEHTYPE", "best", 5.0, 8.0, scripted=False)
        sim.step()
        sim.skip_ahead(sim.time + 3.0)
        state = sim.state
        full = sim.full_state
        assert np.array_equal(state.ids, full.ids[_expected(full, "ego", RADIUS)])
        sim.run_bare(sim.time + 2.0)
        state = sim.step()
        full = sim.full_state
        assert np.array_equal(state.ids, full.ids[_expected(full, "ego", RADIUS)])


def test_collisions_in_scope_only_among_scoped_actors(intersection_net, intersection_demand):
    scope = ReadScope("ego", RADIUS)
    with Simulation(_config(intersection_net, intersection_demand, scope)) as sim:
        sim.fast_forward(60.0)
        sim.add_vehicle("ego", ROUTE, "DEFAULT_VEHTYPE", "best", 5.0, 8.0, scripted=False)
        for _ in range(100):
            state = sim.step()
            ids = set(state.ids.tolist())
            assert all(c.a in ids and c.b in ids for c in sim.collisions)


@pytest.mark.parametrize("scope", [ReadScope("", 50.0), ReadScope("ego", 0.0)])
def test_impossible_scope_is_refused(intersection_net, intersection_demand, scope):
    with pytest.raises(HiyariError, match="read scope"):
        _config(intersection_net, intersection_demand, scope).validate()
