"""Cost of recording a run, file size per simulated minute, and replay load time.

1. Closed loop (the headline): the demo's dart-out with camera, radar and a 64 x 2,048 LiDAR
   at 10 Hz, run unrecorded (the baseline), recorded with every raw LiDAR point as
   ``hiyari.LidarScan`` (the default: quantised at 4 mm range steps, delta-coded byte planes +
   zstd) plus a 1-in-32 ``foxglove.PointCloud`` for display, and recorded with every point as
   a float32 ``foxglove.PointCloud`` (the previous encoding) - the same run, interleaved.
   Reported: wall time ratio to the baseline (median of ``--reps``), MB per simulated minute
   of each recording and their ratio against the target (<= 100 MB per simulated minute),
   payload per topic, bytes per LiDAR point, and the static replay page's size.
2. Traffic overhead: the same city run (same demand and seed, warmed up untimed) stepped with
   no recording (the baseline), recording its ground truth (OSI GroundTruth + Foxglove boxes
   every step), + the OSI road, and + one LiDAR-sized point cloud per step (57,600 points of
   a fixed synthetic ground scan, so only the recorder's cost is measured).
3. Replay load: a city run recorded from t = 0, opened with hiyari's Recording (index every
   message) and drawn in a viser scene; the baseline is reading every message of the same
   file with the mcap library's own reader.

File sizes are deterministic; wall times depend on the machine's load (printed).

Run: .venv/bin/python benchmarks/recording.py [--parts closed-loop,traffic,replay] [--reps 1]
     [--warm 60] [--measure 30] [--replay-minutes 2]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from mcap.reader import make_reader

from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.loop.toml_runs import preset_spec
from hiyari.bridge.loop.traffic_recording import record_traffic
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.bridge.record import format as fmt
from hiyari.bridge.record.reader import Recording
from hiyari.bridge.record.recorder import Recorder, RecorderConfig
from hiyari.bridge.replay.export import export_html
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


def _topic_bytes(path: Path) -> dict[str, int]:
    """Payload bytes per topic group (messages as stored, before chunk compression)."""
    out: dict[str, int] = {}
    with path.open("rb") as f:
        for _, channel, message in make_reader(f).iter_messages(log_time_order=False):
            topic = channel.topic
            group = (
                topic if topic.startswith(fmt.TOPIC_LIDAR) else "/" + topic.split("/")[1] + "/..."
            )
            out[group] = out.get(group, 0) + len(message.data)
    return out


def _read_back(compact: Path, old: Path) -> str:
    """Reading every LiDAR scan back (file opened fresh, chunks decompressed): median ms per
    scan of 3 interleaved rounds, compact against float32."""
    times: dict[Path, list[float]] = {compact: [], old: []}
    for _ in range(3):
        for path in (old, compact):
            rec = Recording.open(path)
            sensor = rec.lidar_sensors[0]
            n = len(rec.message_times(fmt.TOPIC_LIDAR + sensor))
            t0 = time.perf_counter()
            for i in range(n):
                rec.point_cloud_at(sensor, i)
            times[path].append((time.perf_counter() - t0) / n * 1e3)
    new_ms, old_ms = (float(np.median(times[p])) for p in (compact, old))
    return (
        f"reading a scan back (Recording.point_cloud_at): {new_ms:.1f} ms from hiyari.LidarScan, "
        f"{old_ms:.1f} ms from float32 PointCloud (baseline), ratio {new_ms / old_ms:.2f}"
    )


def closed_loop_recording(d: Path, reps: int) -> str:
    """The demo's dart-out with camera, radar and LiDAR: unrecorded (baseline), recorded with
    raw LiDAR as hiyari.LidarScan (the default) and as float32 foxglove.PointCloud (the
    previous encoding); interleaved, median wall times; file sizes per simulated minute."""
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
    configs = {
        "closed loop, no recording (baseline)": None,
        "recorded, raw LiDAR as hiyari.LidarScan": RecorderConfig(),
        "recorded, raw LiDAR as float32 PointCloud": RecorderConfig(lidar_encoding="float32"),
    }
    walls: dict[str, list[float]] = {name: [] for name in configs}
    paths: dict[str, Path] = {}
    sim_s = 0.0
    for rep in range(reps):
        for k, (name, config) in enumerate(configs.items()):
            out = d / f"cl{k}_{rep}"
            opts = RunOptions(out_dir=out, record=config is not None, recorder=config)
            res = execute(preset_spec(cs, out / "roads"), opts)
            walls[name].append(res.wall_seconds)
            sim_s = res.sim_seconds
            if config is not None:
                paths[name] = out / "run.mcap"
    base = float(np.median(walls["closed loop, no recording (baseline)"]))
    compact, old = list(configs)[1:]
    rec = Recording.open(paths[compact])
    scans = [rec.point_cloud_at(s, i) for s in rec.lidar_sensors for i in range(0, 10)]
    points = float(np.mean([len(pc) for pc in scans]))
    lines = [
        f"\nclosed-loop demo (dart-out, LiDAR {rec.lidar_sensors} 10 Hz, {points:,.0f} points a "
        f"scan; radar 20 Hz; camera images every 10th frame), {sim_s:.1f} s simulated, "
        f"median of {reps}",
        f"{'run':44s} {'wall s':>7s} {'ratio':>6s} {'MB / sim min':>13s}",
    ]
    mb_min = {}
    for name in configs:
        wall = float(np.median(walls[name]))
        size = paths[name].stat().st_size if name in paths else 0
        mb_min[name] = size / 2**20 / (sim_s / 60.0)
        shown = f"{mb_min[name]:13.1f}" if name in paths else ""
        lines.append(f"{name:44s} {wall:7.2f} {wall / base:6.2f} {shown}")
    ratio = mb_min[compact] / mb_min[old]
    verdict = "met" if mb_min[compact] <= 100.0 else "NOT met"
    lines.append(
        f"raw LiDAR recording: {mb_min[compact]:.1f} MB per simulated minute, "
        f"{ratio:.3f} x the float32 encoding of the same run ({mb_min[old]:.1f}); "
        f"target <= 100 MB per simulated minute: {verdict}"
    )
    groups = _topic_bytes(paths[compact])
    scan_topics = [t for t in groups if t.startswith(fmt.TOPIC_LIDAR)]
    parts = ", ".join(
        f"{t} {groups[t] / 2**20 / (sim_s / 60.0):.1f}"
        for t in sorted(groups, key=groups.get, reverse=True)[:6]
    )
    lines.append(f"payload MB per simulated minute by topic (before chunk zstd): {parts}")
    for t in scan_topics:
        if not t.endswith(fmt.LIDAR_THINNED_SUFFIX):
            n_scans = len(rec.message_times(t))
            per_point = groups[t] / (n_scans * points)
            lines.append(f"{t}: {per_point:.2f} bytes a point (float32 fields: 24 before zstd)")
    lines.append(_read_back(paths[compact], paths[old]))
    pages = {
        every: export_html(rec, d / f"replay_{every}.html", progress=False, lidar_every=every)
        .stat()
        .st_size
        / 2**20
        for every in (1, 8)
    }
    lines.append(
        f"static replay page: {pages[8]:.1f} MB with 1 in 8 LiDAR points, "
        f"{pages[1]:.1f} MB with every point (ratio {pages[8] / pages[1]:.2f}; "
        f"target <= 15 MB for the demo's 15 s dart-out, baseline 137 MB)"
    )
    return "\n".join(lines)


def traffic_overhead(d: Path, config: SimConfig, warm: float, measure: float) -> str:
    """Traffic-only runs: no recording (baseline), ground truth, + OSI road, + a LiDAR scan."""
    with Simulation(config) as sim:
        for _ in sim.run(until=warm):
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
    walls: dict[str, list[float]] = {name: [] for name in runs}
    sizes: dict[str, int] = {}
    for rep in range(2):  # interleaved, the better of two: less noise from other processes
        for k, (name, (work, record)) in enumerate(runs.items()):
            path = d / f"run{k}_{rep}.mcap"
            rec = Recorder(path, {"scenario": "benchmark"}) if record else None
            walls[name].append(work(rec, warm, measure))
            sizes[name] = path.stat().st_size if record else 0
    base = min(walls["traffic, no recording (baseline)"])
    lines = [
        f"\ncity grid, {actors[0]} vehicles and {actors[1]} pedestrians in the network after "
        f"{warm:.0f} s; {measure:.0f} s simulated per run (0.1 s steps)",
        f"{'run':44s} {'wall s':>7s} {'ratio':>6s} {'MB / sim min':>13s}",
    ]
    for name in runs:
        wall = min(walls[name])
        mb_min = sizes[name] / 2**20 / (measure / 60.0)
        lines.append(f"{name:44s} {wall:7.2f} {wall / base:6.2f} {mb_min:13.2f}")
    return "\n".join(lines)


def replay(d: Path, config: SimConfig, minutes: float) -> str:
    """Replay load of a ground-truth recording of ``minutes`` of the city."""
    long = record_traffic(
        config, minutes * 60, d / "long.mcap", {"scenario": "replay load"}, progress=False
    )
    baseline, opened, first = replay_load(long.path)
    return "\n".join(
        [
            f"\nreplay load, {minutes:.0f}-minute city run "
            f"({long.frames} frames, {long.size_bytes / 2**20:.1f} MB, ground truth only)",
            f"{'step':44s} {'s':>7s} {'ratio':>6s}",
            f"{'mcap reader, every message (baseline)':44s} {baseline:7.3f} {1.0:6.2f}",
            f"{'Recording.open (index)':44s} {opened:7.3f} {opened / baseline:6.2f}",
            f"{'open + replay scene + frame drawn':44s} {first:7.3f} {first / baseline:6.2f}",
        ]
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--parts",
        default="closed-loop,traffic,replay",
        help="comma-separated: closed-loop, traffic, replay",
    )
    ap.add_argument("--reps", type=int, default=1, help="closed-loop repetitions (median)")
    ap.add_argument("--warm", type=float, default=60.0, help="traffic: untimed warm-up, s")
    ap.add_argument("--measure", type=float, default=30.0, help="traffic: timed window, s")
    ap.add_argument("--replay-minutes", type=float, default=2.0, help="length of the replay run")
    args = ap.parse_args()
    parts = set(args.parts.split(","))
    print(f"load average at start: {os.getloadavg()[0]:.2f} (1 min) on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        d = Path(tmp)
        if "closed-loop" in parts:
            print(closed_loop_recording(d, args.reps), flush=True)
        if parts & {"traffic", "replay"}:
            net = build_city_grid(d / "city.net.xml", CityGridParams())
            end = max(args.warm + args.measure, args.replay_minutes * 60)
            demand = write_demand(
                net,
                d / "demand.rou.xml",
                DemandConfig(vehicles_per_hour=2400, persons_per_hour=2400, end=end, seed=1),
            )
            config = SimConfig(net=net, routes=[demand], seed=1)
            if "traffic" in parts:
                print(traffic_overhead(d, config, args.warm, args.measure), flush=True)
            if "replay" in parts:
                print(replay(d, config, args.replay_minutes), flush=True)
    print(f"load average at end: {os.getloadavg()[0]:.2f} (1 min)")


if __name__ == "__main__":
    main()
