"""Record a city run to MCAP and replay it in the browser.

Builds a 3 x 3 block city grid with vehicles and pedestrians, records every step (ASAM OSI
ground truth, Foxglove boxes, the road mesh, contacts) with the first vehicle marked as the
ego, then serves the replay on http://127.0.0.1:8080/ (or writes a static HTML replay).
Traffic only: sensor outputs, object lists and the ego status appear in recordings of
closed-loop runs, which attach the same Recorder.

Run:   .venv/bin/python examples/replay_city.py [--duration 120] [--export]
Later: .venv/bin/hiyari replay out/replay_city/city.mcap
"""

from __future__ import annotations

import argparse
import threading
from pathlib import Path

from hiyari.bridge.loop.traffic_recording import record_simulation
from hiyari.bridge.record.reader import Recording
from hiyari.bridge.record.recorder import Recorder
from hiyari.net.mesh.road_mesh import build_scene_mesh
from hiyari.net.road.geometry import RoadGeometry
from hiyari.net.sumo.build import CityGridParams, build_city_grid
from hiyari.traffic import DemandConfig, SimConfig, Simulation, write_demand


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("out/replay_city"), help="output folder")
    ap.add_argument("--duration", type=float, default=120.0, help="simulated seconds")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--port", type=int, default=8080)
    ap.add_argument("--export", action="store_true", help="write replay.html instead of serving")
    args = ap.parse_args()

    out = args.out
    net = build_city_grid(out / "city.net.xml", CityGridParams(blocks_x=3, blocks_y=3))
    demand = DemandConfig(
        vehicles_per_hour=1800,
        persons_per_hour=1800,
        end=args.duration,
        seed=args.seed,
        vehicle_mix={"car": 0.8, "truck": 0.05, "bus": 0.05, "motorcycle": 0.05, "bicycle": 0.05},
    )
    routes = write_demand(net, out / "demand.rou.xml", demand)
    mesh = build_scene_mesh(RoadGeometry.from_net(net))
    path = out / "city.mcap"
    meta = {"scenario": "city grid 3x3, traffic only", "seed": args.seed, "demand": demand}
    with (
        Simulation(SimConfig(net=net, routes=[routes], seed=args.seed)) as sim,
        Recorder(path, meta) as rec,
    ):
        rec.write_static_mesh(mesh)
        steps = record_simulation(sim, rec, args.duration, ego_id="veh0", progress=True)
    print(f"recorded {steps} steps to {path} ({path.stat().st_size / 2**20:.1f} MiB)")

    recording = Recording.open(path)
    if args.export:
        from hiyari.bridge.replay.export import export_html

        html = export_html(recording, out / "replay.html")
        print(f"static replay: {html} (open it in a browser)")
        return
    from hiyari.bridge.replay.server import ReplayApp

    app = ReplayApp(recording, port=args.port)
    print(f"replay at {app.url} (Ctrl-C to stop)")
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        pass
    finally:
        app.close()


if __name__ == "__main__":
    main()
