"""Several simulations in one process: a run that ends right after placing actors must not
leave libsumo's pending moveToXY requests to the next run (a segfault in its first step)."""

from __future__ import annotations

from hiyari.traffic import SimConfig, Simulation

ROUTE = ("w_in", "e_out")


def _placed_then_closed(net) -> None:
    with Simulation(SimConfig(net=net, step_length=0.1, seed=1)) as sim:
        sim.add_person("ped", "w_in", 85.0, "DEFAULT_PEDTYPE", wait=100.0)
        sim.add_vehicle("car", ROUTE, "DEFAULT_VEHTYPE", "best", 20.0, 10.0, scripted=True)
        sim.step()
        car, ped = sim.state.index("car"), sim.state.index("ped")
        x, y = sim.state.xyz[car, :2]
        sim.move_vehicle("car", x + 1.0, y, sim.state.heading[car], 5.0, speed=10.0)
        px, py = sim.state.xyz[ped, :2]
        sim.move_person("ped", px, py + 0.5, 0.0)
        # closed here, before the step that would apply the moves


def test_a_run_closed_with_moves_pending_does_not_break_the_next(intersection_net):
    _placed_then_closed(intersection_net)
    # the same ids again: libsumo's table of pending moves would point at freed actors
    with Simulation(SimConfig(net=intersection_net, step_length=0.1, seed=1)) as sim:
        sim.add_person("ped", "w_in", 85.0, "DEFAULT_PEDTYPE", wait=100.0)
        sim.add_vehicle("car", ROUTE, "DEFAULT_VEHTYPE", "best", 20.0, 10.0, scripted=False)
        states = [sim.step() for _ in range(20)]
    assert {"car", "ped"} <= set(states[-1].ids.tolist())
    assert states[-1].time == 2.0
