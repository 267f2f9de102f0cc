"""Cost of recording a run, file size per simulated minute, and replay load time.

1. Overhead: the same run (city grid, same demand and seed, warmed up untimed) stepped with
   no recording (the baseline), recording its ground truth (OSI GroundTruth + Foxglove boxes
   every step), and ground truth plus one LiDAR-sized point cloud per step (57,600 points, a
   32-channel scan at 10 Hz; the points are a fixed synthetic ground scan, the same array
   every step, so only the recorder's cost is measured). Reported: wall time ratio to the
   baseline and MB per simulated minute.
2. Replay load: a 5-minute city run recorded from t = 0, then opened with hiyari's Recording
   (index every message) and drawn to its first frame in a viser scene; the baseline is
   reading every message of the same file with the mcap library's own reader.

3. The closed-loop demo (dart-out with camera, radar and LiDAR) with and without recording
   everything (ground truth, raw sensor outputs, object lists, tracks, ego status), and the
   size of its static replay page (bridge/replay/export.py) with 1 in 8 LiDAR points (the
   default) next to the page with every point.

Run: .venv/bin/python benchmarks/recording.py [--warm 120] [--measure 60] [--replay-minutes 5]
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from mcap.reader import make_reader

from hiyari.bridge.record.reader import Recording
from hiyari.bridge.record.recorder import Recorder
from hiyari.bridge.record.traffic import record_traffic
from hiyari.bridge.replay.export import export_html
from hiyari.bridge.scenario.run import RunOptions, run_concrete
from hiyari.bridge.scenario.toml_file import ConcreteScenario
from hiyari.net.road.geometry import RoadGeometry
from hiyari.net.sumo.build import CityGridParams, build_city_grid
from hiyari.sensors.outputs import HIT_STATIC, PointCloud
from hiyari.traffic import DemandConfig, SimConfig, Simulation, write_demand

Workload = Callable[[Recorder | None, float, float], float]


def lidar_scan(channels: int = 32, azimuth_steps: int = 1800, height: float = 1.8) -> PointCloud:
    """A ground scan of a roof LiDAR: every beam meets flat ground (or 100 m), with noise."""
    rng = np.random.default_rng(0)
    elev = np.radians(np.linspace(-25.0, 15.0, channels))
    az = np.linspace(-np.pi, np.pi, azimuth_steps, endpoint=False)
    e, a = np.meshgrid(elev, az, indexing="ij")
    r = np.where(e < 0, height / np.sin(-np.minimum(e, -1e-3)), 100.0).clip(max=100.0)
    r = (r + rng.normal(0, 0.02, r.shape)).ravel()
    e, a = e.ravel(), a.ravel()
    xyz = np.stack([r * np.cos(e) * np.cos(a), r * np.cos(e) * np.sin(a), r * np.sin(e)], 1)
    n = len(r)
    return PointCloud(
        time=0.0,
        sensor="top",
        sensor_to_world=np.eye(4),
        xyz=xyz.astype(np.float32),
        intensity=(0.1 + 0.05 * rng.random(n)).astype(np.float32),
        range=r.astype(np.float32),
        hit=np.full(n, HIT_STATIC, np.int32),
        actor_ids=np.zeros(0, dtype=object),
    )


def traffic(config: SimConfig, lidar: PointCloud | None, road: bool = False) -> Workload:
    """Traffic-only run; with ``lidar``, that scan is recorded at every step as well; with
    ``road``, the OSI road (lanes, boundaries, traffic lights and their states) too."""

    def run(recorder: Recorder | None, warm: float, measure: float) -> float:
        with Simulation(config) as sim:
            for _ in sim.run(until=warm):
                pass
            lights: list[str] = []
            if recorder is not None and road:
                recorder.write_road(RoadGeometry.from_net(config.net), None, sim.signal_links())
                lights = recorder.signal_ids
            t0 = time.perf_counter()
            for state in sim.run(until=warm + measure):
                if recorder is not None:
                    signals = sim.signal_states(lights) if lights else None
                    recorder.write_world(state, collisions=sim.collisions, signals=signals)
                    if lidar is not None:
                        recorder.write_point_cloud(dataclasses.replace(lidar, time=state.time))
            wall = time.perf_counter() - t0
            if recorder is not None:
                recorder.close()
            return wall

    return run


def replay_load(path: Path) -> tuple[float, float, float]:
    """(mcap reader s, Recording.open s, open + first frame drawn s) for one file."""
    import viser

    from hiyari.bridge.replay.scene import ReplayScene

    t0 = time.perf_counter()
    with path.open("rb") as f:
        n = sum(1 for _ in make_reader(f).iter_messages(log_time_order=False))
    baseline = time.perf_counter() - t0
    assert n > 0
    t0 = time.perf_counter()
    rec = Recording.open(path)
    opened = time.perf_counter() - t0
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        t0 = time.perf_counter()
        rec = Recording.open(path)
        ReplayScene(server, rec).draw(len(rec) // 2)
        first = time.perf_counter() - t0
    finally:
        server.stop()
    return baseline, opened, first


def closed_loop_overhead(d: Path) -> str:
    """The demo's dart-out with camera, radar and LiDAR, with and without recording."""
    cs = ConcreteScenario(
        "dart-out",
        "benchmark dart-out",
        0,
        1,
        12.0,
        0.05,
        {"ve0_kmh": 40.0, "ped_speed_kmh": 5.0, "impact_fraction": 0.5, "parked_car": 1.0},
        perception="sensors",
    )
    plain = run_concrete(cs, RunOptions(out_dir=d / "cl_plain", plot=False))
    rec = run_concrete(cs, RunOptions(out_dir=d / "cl_rec", plot=False, record=True))
    size = (d / "cl_rec" / "run.mcap").stat().st_size
    mb_min = size / 2**20 / (rec.sim_seconds / 60.0)
    recording = Recording.open(d / "cl_rec" / "run.mcap")
    pages = {
        every: export_html(recording, d / f"replay_{every}.html", progress=False, lidar_every=every)
        .stat()
        .st_size
        / 2**20
        for every in (1, 8)
    }
    return (
        f"\nclosed-loop demo (dart-out, LiDAR 10 Hz + radar 20 Hz + camera, images every 10th "
        f"frame), {rec.sim_seconds:.1f} s simulated\n"
        f"{'closed loop, no recording (baseline)':44s} {plain.wall_seconds:7.2f} {1.0:6.2f}\n"
        f"{'closed loop, everything recorded':44s} {rec.wall_seconds:7.2f} "
        f"{rec.wall_seconds / plain.wall_seconds:6.2f} {mb_min:13.2f}\n"
        f"static replay page: {pages[8]:.1f} MB with 1 in 8 LiDAR points, "
        f"{pages[1]:.1f} MB with every point (ratio {pages[8] / pages[1]:.2f}; "
        f"target <= 15 MB for the demo's 15 s dart-out, baseline 137 MB)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--warm", type=float, default=120.0, help="untimed warm-up, s")
    ap.add_argument("--measure", type=float, default=60.0, help="timed window, s")
    ap.add_argument("--replay-minutes", type=float, default=5.0, help="length of the replay run")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        d = Path(tmp)
        net = build_city_grid(d / "city.net.xml", CityGridParams())
        end = max(args.warm + args.measure, args.replay_minutes * 60)
        demand = write_demand(
            net,
            d / "demand.rou.xml",
            DemandConfig(vehicles_per_hour=2400, persons_per_hour=2400, end=end, seed=1),
        )
        config = SimConfig(net=net, routes=[demand], seed=1)
        with Simulation(config) as sim:
            for _ in sim.run(until=args.warm):
                pass
            state = sim.state
            actors = (int(state.is_vehicle.sum()), int(state.is_pedestrian.sum()))
        lidar = lidar_scan()
        runs: dict[str, tuple[Workload, bool]] = {
            "traffic, no recording (baseline)": (traffic(config, None), False),
            "traffic, ground truth recorded": (traffic(config, None), True),
            "traffic, ground truth + OSI road recorded": (traffic(config, None, road=True), True),
            f"traffic + LiDAR {len(lidar)} pts/step recorded": (traffic(config, lidar), True),
        }
        rows = []
        for name, (work, record) in runs.items():
            walls, size = [], 0
            for rep in range(2):  # the better of two runs: less noise from other processes
                path = d / f"run{len(rows)}_{rep}.mcap"
                rec = Recorder(path, {"scenario": "benchmark"}) if record else None
                walls.append(work(rec, args.warm, args.measure))
                size = path.stat().st_size if record else 0
            rows.append((name, min(walls), size))
        base = rows[0][1]
        print(
            f"city grid, {actors[0]} vehicles and {actors[1]} pedestrians in the network after "
            f"{args.warm:.0f} s; {args.measure:.0f} s simulated per run (0.1 s steps)"
        )
        print(f"{'run':44s} {'wall s':>7s} {'ratio':>6s} {'MB / sim min':>13s}")
        for name, wall, size in rows:
            mb_min = size / 2**20 / (args.measure / 60.0)
            print(f"{name:44s} {wall:7.2f} {wall / base:6.2f} {mb_min:13.2f}")

        print(closed_loop_overhead(d))

        long = record_traffic(
            config,
            args.replay_minutes * 60,
            d / "long.mcap",
            {"scenario": "replay load"},
            progress=False,
        )
        baseline, opened, first = replay_load(long.path)
        print(
            f"\nreplay load, {args.replay_minutes:.0f}-minute city run "
            f"({long.frames} frames, {long.size_bytes / 2**20:.1f} MB, ground truth only)"
        )
        print(f"{'step':44s} {'s':>7s} {'ratio':>6s}")
        print(f"{'mcap reader, every message (baseline)':44s} {baseline:7.3f} {1.0:6.2f}")
        print(f"{'Recording.open (index)':44s} {opened:7.3f} {opened / baseline:6.2f}")
        print(f"{'open + replay scene + frame drawn':44s} {first:7.3f} {first / baseline:6.2f}")


if __name__ == "__main__":
    main()
