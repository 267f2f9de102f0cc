"""Where the actors of the Euro NCAP 2023 files meet: each of the 13 concrete files of
../shared/data/openscenario/ncap run on SUMO with the ego held at its Init speed (the protocol's
unbraked test: no stack, no AEB), and for each file

- whether it runs to a stop (its stop trigger) or a first contact;
- for the files whose target synchronizes with the ego (SynchronizeAction): the target's
  distance to its synchronization point (the protocol's impact point) at the moment the ego
  reaches its own, interpolated between the steps (``sync error``, m; positive: short of it);
- at the first contact: the target's box centre in the ego frame (x ahead of the ego's
  reference point, y to its left, m) and the ego speed.

    .venv/bin/python benchmarks/ncap_meeting.py [--dt 0.05] [--out docs/ncap_meeting.md]
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from hiyari.bridge.openscenario.engine import ScenarioEngine
from hiyari.bridge.openscenario.engine.followers.synchronize import Synchronizer
from hiyari.bridge.openscenario.model.actions import SynchronizeAction
from hiyari.bridge.openscenario.xosc.reader import read_scenario
from hiyari.checkout import shared_dir
from hiyari.net.road.opendrive_lanes import RoadLanes
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.traffic.simulation import SimConfig, Simulation

NCAP = shared_dir() / "data" / "openscenario" / "ncap"
FILES = sorted((NCAP / "OpenSCENARIO" / "NCAP").glob("AEB_*_2023/*.xosc"))


def _syncs(sc: object) -> list[tuple[str, SynchronizeAction]]:
    out = []
    for story in sc.storyboard.stories:
        for act in story.acts:
            for g in act.groups:
                for m in g.maneuvers:
                    for ev in m.events:
                        for a in ev.actions:
                            if isinstance(a.body, SynchronizeAction):
                                out += [(actor, a.body) for actor in g.actors]
    return out


def measure(path: Path, dt: float, nets: dict, work: Path) -> dict:
    """One file's row (see the module)."""
    sc = read_scenario(path)
    xodr = sc.road_network
    if xodr not in nets:
        nets[xodr] = import_opendrive(xodr, work / f"{xodr.stem}.net.xml")
    roads = RoadLanes.from_files(xodr, nets[xodr])
    row: dict = {"file": path.stem.replace("NCAP_AEB_", "").replace("_2023", "")}
    with Simulation(SimConfig(net=nets[xodr], step_length=dt)) as sim:
        engine = ScenarioEngine(sc, roads, dt)
        report = engine.start(sim)
        v0 = abs(engine.actors[sc.ego].v)
        probes = [Synchronizer(engine, actor, body) for actor, body in _syncs(sc)]
        last: list[tuple[float, float] | None] = [None] * len(probes)
        while not report.finished and sim.time < 120.0:
            world = sim.step()
            engine.now = world.time - engine.t0
            engine._world, engine._located = world, {}
            engine._map_rows(world)
            for k, p in enumerate(probes):  # before the update: the actors as SUMO has them
                dm, d = p.remaining(p.b.master, p.b.master_target), p.remaining(p.actor, p.b.target)
                if last[k] is not None and last[k][0] > 0 >= dm and "sync error" not in row:
                    f = last[k][0] / (last[k][0] - dm)
                    row["sync error"] = last[k][1] + f * (d - last[k][1])
                last[k] = (dm, d)
            report = engine.step(sim, world)
            hit = [c for c in sim.collisions if sc.ego in (c.a, c.b) and c.depth > 0]
            if hit:
                other = hit[0].b if hit[0].a == sc.ego else hit[0].a
                e, o = world.index(sc.ego), world.index(other)
                h = float(world.heading[e])
                if engine.ego_path is not None and engine.ego_path.reverse:
                    h += math.pi
                ent = engine.actors[sc.ego].entity
                c, s = math.cos(h), math.sin(h)
                ref = world.xyz[e, :2] - np.array([ent.centre[0] * c, ent.centre[0] * s])
                d = world.xyz[o, :2] - ref
                row.update(contact=other, x=d[0] * c + d[1] * s, y=-d[0] * s + d[1] * c,
                           t=engine.now, v=float(world.speed[e]))  # fmt: skip
                break
            if not report.ego_storyboard_driven:
                engine.drive_ego(sim, v0)
        row["end"] = (
            "stop trigger" if report.finished else ("contact" if "contact" in row else "time")
        )
    return row


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dt", type=float, default=0.05)
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args()
    lines = [
        "| file | sync error (m) | contact | at t (s) | x, y in the ego frame (m) | ego speed (m/s) | end |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    nets: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        for f in FILES:
            r = measure(f, args.dt, nets, Path(tmp))
            se = f"{r['sync error']:+.3f}" if "sync error" in r else "-"
            if "contact" in r:
                at = f"{r['x']:+.2f}, {r['y']:+.2f}"
                line = f"| {r['file']} | {se} | {r['contact']} | {r['t']:.2f} | {at} | {r['v']:.2f} | {r['end']} |"
            else:
                line = f"| {r['file']} | {se} | - | - | - | - | {r['end']} |"
            lines.append(line)
            print(line, flush=True)
    if args.out:
        args.out.write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
