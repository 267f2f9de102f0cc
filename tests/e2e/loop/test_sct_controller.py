"""The SCT driver model: profiles, scope, and a real SUMO car slowing for a kerb pedestrian."""

from __future__ import annotations

import numpy as np
import pytest
from sct_reference import ramp_profiles

from hiyari.bridge.loop.drivers.sct_controller import (
    G,
    SCTController,
    SCTControllerConfig,
    travel,
)
from hiyari.errors import HiyariError
from hiyari.net.sumo.build import IntersectionParams, build_intersection
from hiyari.risk.metrics.pedestrian_geometry import NetGeometry
from hiyari.risk.sct.model import SCTModel
from hiyari.traffic import SimConfig, Simulation

pytestmark = pytest.mark.timeout(120)


def test_ramps_respect_the_bounds():
    cfg = SCTControllerConfig()
    t = np.arange(0, 10.001, 0.01)
    targets = np.array(cfg.targets_g) * G
    a = ramp_profiles(1.0, targets, t, cfg.jerk_limit)
    assert np.allclose(a[:, 0], 1.0) and np.allclose(a[:, -1], targets)
    jerk = np.abs(np.diff(a, axis=1)) / 0.01
    assert jerk.max() <= cfg.jerk_limit + 1e-6
    assert jerk[:, 0].max() == pytest.approx(cfg.jerk_limit, rel=0.01)  # full jerk at once
    assert a.min() >= -0.4 * G - 1e-9 and a.max() <= max(1.0, 0.15 * G) + 1e-9


def test_travel_stops_and_stays_stopped():
    t = np.arange(0, 10.001, 0.1)
    v, s = travel(np.full((1, len(t)), -2.0), 10.0, 14.0, 0.1)
    assert v[0, -1] == 0.0 and s[0, -1] == pytest.approx(25.0, abs=0.01)  # v^2 / 2a
    crawl, _ = travel(np.full((1, len(t)), -0.2), 1.5, 14.0, 0.1, stop_speed=1.0)
    assert crawl[0, 30] == 0.0  # below 1 m/s after 2.5 s: a full stop instead of a crawl
    assert np.all(v <= 14.0)


def test_penetration_scope_is_seeded_and_nested():
    ids = [f"veh{k}" for k in range(3000)]
    low = SCTController(SCTModel(None), SCTControllerConfig(penetration=0.3), seed=5)
    high = SCTController(SCTModel(None), SCTControllerConfig(penetration=0.6), seed=5)
    a = {i for i in ids if low.in_scope(i)}
    b = {i for i in ids if high.in_scope(i)}
    assert a <= b
    assert len(a) / len(ids) == pytest.approx(0.3, abs=0.03)
    assert len(b) / len(ids) == pytest.approx(0.6, abs=0.03)
    with pytest.raises(HiyariError, match="penetration"):
        SCTControllerConfig(penetration=1.5).validate()


ROUTES = """<routes>
<vType id="car" vClass="passenger" length="4.5" width="1.8" speedFactor="1" speedDev="0"/>
<vType id="pedestrian" vClass="pedestrian"/>
<person id="ped0" type="pedestrian" depart="0">
  <stop lane="n_in_0" endPos="120" duration="1000"/>
</person>
<trip id="car0" type="car" depart="1" from="n_in" to="s_out" departSpeed="max"/>
</routes>
"""


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sct_scene")
    net = build_intersection(folder / "x.net.xml", IntersectionParams(traffic_light=False))
    routes = folder / "scene.rou.xml"
    routes.write_text(ROUTES)
    return net, routes


def approach_speeds(net, routes, sct: bool) -> tuple[np.ndarray, np.ndarray, float]:
    """Run the scene; the car's centre y and speed each step until it passes the pedestrian,
    and the pedestrian's y.

    The pedestrian stands 0.8 m off the kerb of the car's lane, 30 m before the junction,
    facing the road (held there with moveToXY); the car drives down that lane.
    """
    geometry = NetGeometry.from_net(net)
    k = geometry.kerbs
    cy = float(geometry.junction_xy[0, 1])
    kerb = (k.crossing < 0) & np.isclose(k.inward[:, 0], 1.0) & (k.a[:, 1] > cy)
    ped_x, ped_y = float(k.a[np.flatnonzero(kerb)[0], 0]) - 0.8, cy + 30.0
    model = SCTModel(geometry)
    ctrl = SCTController(model)
    ys, vs = [], []
    with Simulation(SimConfig(net=net, routes=[routes], seed=1), detect_collisions=False) as sim:
        for _ in range(400):
            st = sim.step()
            if "ped0" in st.ids and st.time > 0.5:
                sim.move_person("ped0", ped_x, ped_y, 0.0, edge="n_in")  # facing east
            if "car0" not in st.ids:
                continue
            r = st.index("car0")
            ys.append(st.xyz[r, 1])
            vs.append(st.speed[r])
            if st.xyz[r, 1] < ped_y - 5.0:
                break
            if sct and st.time > 1.0:
                if not model.has_route("car0"):
                    model.set_route("car0", sim.route_of("car0"))
                ctrl.step(sim, model.prepare(st))
    return np.array(ys), np.array(vs), ped_y


def test_sct_car_slows_for_a_kerb_pedestrian_where_sumo_does_not(scene):
    y_base, v_base, ped_y = approach_speeds(*scene, False)
    y_sct, v_sct, _ = approach_speeds(*scene, True)
    near = (y_base > ped_y) & (y_base < ped_y + 40.0)
    assert v_base[near].min() > 13.0  # SUMO's driver keeps the 50 km/h limit
    near = (y_sct > ped_y) & (y_sct < ped_y + 40.0)
    assert near.any()
    assert v_sct[near].min() < 0.5 * v_base.max()
    # it comes to a stop short of the pedestrian (it may step in at any moment) and waits
    assert v_sct.min() < 0.5 and y_sct.min() > ped_y
