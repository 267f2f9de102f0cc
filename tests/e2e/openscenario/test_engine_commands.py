"""The engine's batched commands into real SUMO (libsumo's SWIG functions driven by map):
fronts placed where commanded, speeds set or held (NaN), lengths checked."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from paths import REPO_ROOT

from hiyari.checkout import shared_dir
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.traffic.commands import VehicleType, heading_to_sumo_angle
from hiyari.traffic.simulation import SimConfig, Simulation

XODR = shared_dir(REPO_ROOT) / "data/openscenario/alks/road_networks/alks_road_straight.xodr"
LENGTH = 5.0


@pytest.fixture(scope="module")
def straight_net(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return import_opendrive(XODR, tmp_path_factory.mktemp("net") / "straight.net.xml")


def _two_cars(sim: Simulation) -> None:
    sim.define_vehicle_type(VehicleType("box", LENGTH, 2.0, 1.5, max_speed=60.0))
    edge = next(e for e in sim._api().edge.getIDList() if not e.startswith(":"))
    for name, pos in (("a", 60.0), ("b", 120.0)):
        sim.add_vehicle(name, [edge], "box", "best", pos, 10.0, scripted=True)


def test_fronts_are_placed_and_speeds_set_or_held(straight_net: Path) -> None:
    with Simulation(SimConfig(net=straight_net, step_length=0.05)) as sim:
        _two_cars(sim)
        world = sim.step()
        sim.set_speeds(["a", "b"], [7.0, 7.0])
        world = sim.step()
        heading = {n: float(world.heading[world.ids.tolist().index(n)]) for n in ("a", "b")}
        centre = {n: world.xyz[world.ids.tolist().index(n), :2].copy() for n in ("a", "b")}
        # each car one metre further along its heading; a gets 12 m/s, b keeps the 7 m/s set
        fronts = {
            n: centre[n] + (0.5 * LENGTH + 1.0) * np.array([math.cos(h), math.sin(h)])
            for n, h in heading.items()
        }
        sim.move_vehicle_fronts(
            ["a", "b"],
            ["", ""],
            [-1, -1],
            [float(fronts["a"][0]), float(fronts["b"][0])],
            [float(fronts["a"][1]), float(fronts["b"][1])],
            [heading_to_sumo_angle(heading["a"]), heading_to_sumo_angle(heading["b"])],
            [12.0, math.nan],
        )
        world = sim.step()
        for n, v in (("a", 12.0), ("b", 7.0)):
            row = world.ids.tolist().index(n)
            want = centre[n] + np.array([math.cos(heading[n]), math.sin(heading[n])])
            np.testing.assert_allclose(world.xyz[row, :2], want, atol=1e-6)
            assert world.heading[row] == pytest.approx(heading[n], abs=1e-9)
            assert world.speed[row] == pytest.approx(v)


def test_commands_of_different_lengths_are_refused(straight_net: Path) -> None:
    with Simulation(SimConfig(net=straight_net, step_length=0.05)) as sim:
        _two_cars(sim)
        sim.step()
        with pytest.raises(ValueError, match="set_speeds"):
            sim.set_speeds(["a", "b"], [1.0])
        with pytest.raises(ValueError, match="move_vehicle_fronts"):
            sim.move_vehicle_fronts(["a"], ["", ""], [-1], [0.0], [0.0], [0.0], [1.0])
