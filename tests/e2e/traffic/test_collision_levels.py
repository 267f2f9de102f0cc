"""Actors on two levels of a crossing are not in contact: a car on a bridge passes over the
car below it, although their ground rectangles overlap in plan view."""

from __future__ import annotations

import dataclasses

import numpy as np
from xodr_authoring import SINGLE, opendrive, road, write

from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.traffic import SimConfig, Simulation
from hiyari.traffic.collision import CollisionDetector

BRIDGE_Z = 6.0  # m: above a 1.5 m car by far, below the 10 m of the sg example on purpose


def _crossing(path):
    """Road 1 along +x (x 0..200, z = 0); road 2 along +y (y -100..100 at x = 100), its
    elevation a constant 6 m: the roads cross in plan view at (100, 0) with no junction."""
    root = opendrive()
    road(root, 1, (0.0, 0.0, 0.0), 200.0, SINGLE)
    r2 = road(root, 2, (100.0, -100.0, np.pi / 2), 200.0, SINGLE)
    profile = r2.makeelement("elevationProfile")
    profile.append(profile.makeelement("elevation", s="0", a=repr(BRIDGE_Z), b="0", c="0", d="0"))
    r2.insert(list(r2).index(r2.find("planView")) + 1, profile)
    return write(root, path)


def test_car_on_bridge_passes_over_car_below(tmp_path):
    net = import_opendrive(_crossing(tmp_path / "bridge.xodr"), tmp_path / "b.net.xml",
                           warn=lambda m: None)  # fmt: skip
    flat = CollisionDetector()
    seen_2d, contacts, heights = 0, [], set()
    with Simulation(SimConfig(net=net, step_length=0.1, seed=1)) as sim:
        # SUMO's default car, 5 m x 1.8 m, centre 2.5 m behind the front. The lane centres
        # cross at (101.75, -1.75): 101.75 m along road 1, 98.25 m along road 2. Fronts at
        # 93.5 and 90 m put both centres 10.75 m before it: at 10 m/s they reach it together,
        # and in plan view the cars overlap while both centres are within 2.5 + 0.9 = 3.4 m of
        # it, 0.68 s or 6 to 7 steps of 0.1 s
        sim.add_vehicle("low", ("-1",), "DEFAULT_VEHTYPE", "0", 93.5, 10.0, scripted=True)
        sim.add_vehicle("high", ("-2",), "DEFAULT_VEHTYPE", "0", 90.0, 10.0, scripted=True)
        for vid in ("low", "high"):
            sim.set_speed(vid, 10.0)
        for state in sim.run(until=4.0):
            contacts += sim.collisions
            if len(state) == 2:
                z = np.round(state.xyz[:, 2], 3).tolist()
                heights.add(tuple(sorted(zip(state.ids, z, strict=True))))
                ground = dataclasses.replace(state, xyz=state.xyz * [1.0, 1.0, 0.0])
                seen_2d += bool(flat.detect(ground))
    assert heights == {
        (("high", BRIDGE_Z), ("low", 0.0))
    }  # SUMO's 3-D positions: one car on each level
    assert seen_2d in (6, 7), seen_2d  # in plan view the two cars overlap (see above)
    assert contacts == []
