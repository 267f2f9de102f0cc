"""``hiyari demo``: the main jobs on built-in defaults, then where the outputs are."""

from __future__ import annotations

import argparse
import os
import shlex
import time

from hiyari.bridge.cli import numbers
from hiyari.bridge.cli.outputs import output_folder


def _stage(title: str) -> float:
    print(f"\n== {title}", flush=True)
    return time.perf_counter()


def run(args: argparse.Namespace) -> int:
    from hiyari.bridge.cli.demo import closed_loop as cl
    from hiyari.bridge.cli.demo.traffic import run_traffic_demo

    out = output_folder(args.out, "--out")
    t = _stage(f"traffic: signalised city intersection, {args.duration:.0f} s simulated")
    d = run_traffic_demo(out / "traffic", duration=args.duration, seed=args.seed)
    print(
        f"   {d['vehicles_seen']} vehicles and {d['persons_seen']} pedestrians, "
        f"{d['realtime_factor']:.0f}x real time, {len(d['collision_pairs'])} collision pairs "
        f"({time.perf_counter() - t:.1f} s)"
    )
    print(
        f"   contacts by reason: {d['contact_reasons']} (actors, where and why: "
        f"{out / 'traffic' / 'collisions.csv'})"
    )

    t = _stage("C&C driver Preventable boundaries (JAMA Fig. 26/28/30), Ve0 10-130 km/h")
    paths = cl.run_datasheets(out / "datasheets")
    print(f"   {len(paths)} files ({time.perf_counter() - t:.1f} s)")

    t = _stage(
        f"UN R157 test points, {args.r157_sample} judged in closed loop (perfect perception)"
    )
    s = cl.run_r157_sample(out / "r157", args.r157_sample, args.workers)
    print(
        f"   {s['verdict'].upper()}: {s['passed']}/{s['preventable']} Preventable points passed "
        f"({time.perf_counter() - t:.1f} s)"
    )

    for name, stype, params, label in (
        (
            "cut_in",
            "cut-in",
            cl.CUT_IN,
            "expressway cut-in (UN R157 road), Ve0 60 km/h, Vo0 30 km/h, dx0 25 m",
        ),
        (
            "dart_out",
            "dart-out",
            cl.DART_OUT,
            "city dart-out (CPNC-50) from behind a parked car at 40 km/h",
        ),
    ):
        t = _stage(f"closed loop, camera + radar + LiDAR: {label}")
        r = cl.run_sensor_scenario(stype, params, out / name)
        verdict = (
            f"COLLISION at {r['impact_speed_kmh']:.1f} km/h" if r["collision"] else "no collision"
        )
        extra = (
            f", stopped {r['stop_distance_m']:.1f} m before the conflict point"
            if r.get("stop_distance_m") is not None
            else ""
        )
        print(
            f"   {verdict}{extra}; min TTC {r['min_ttc_s']} s; {r['sim_seconds']:.1f} s simulated "
            f"in {r['wall_seconds']:.1f} s ({time.perf_counter() - t:.1f} s with set-up)"
        )
    t = _stage(f"JAMA catalogue: {args.catalogue_runs} runs per motorway cell, safety argument")
    from hiyari.bridge.cli.demo.catalogue import run_catalogue_demo

    command = shlex.join(["hiyari", *args.argv]) + " (its catalogue stage)"
    c = run_catalogue_demo(out / "catalogue", args.catalogue_runs, args.workers, command)
    print(
        f"   {c['verdict']}: {c['passed']}/{c['runs']} runs passed ({c['not_tested']} not "
        f"tested), {c['preventable_passed']}/{c['preventable']} "
        f"Preventable; {c['report']} ({time.perf_counter() - t:.1f} s)"
    )

    t = _stage("replay: static HTML of the dart-out recording")
    html = cl.export_replay(out / "dart_out" / "run.mcap", out / "dart_out" / "replay.html")
    print(f"   {html} ({time.perf_counter() - t:.1f} s)")

    print(f"\noutputs in {out.resolve()}:")
    for f in sorted(p for p in out.rglob("*") if p.is_file() and "roads" not in p.parts):
        print(f"   {f.relative_to(out)}")
    print(
        f"\nlive 3D replay: .venv/bin/hiyari replay {out / 'dart_out' / 'run.mcap'}"
        "  (then open http://127.0.0.1:8080/)"
    )
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="run the main jobs on built-in defaults")
    p.add_argument("--out", default="out/demo", help="output folder")
    p.add_argument(
        "--duration", type=numbers.seconds(), default=300.0, help="traffic seconds to simulate"
    )
    p.add_argument("--r157-sample", type=numbers.count(1), default=60, help="R157 points to judge")
    p.add_argument(
        "--catalogue-runs", type=numbers.count(1), default=2, help="catalogue runs per cell"
    )
    p.add_argument("--workers", "-j", type=numbers.count(1, 4096), default=os.cpu_count() or 1)
    p.add_argument("--seed", type=numbers.seed(), default=42)
    p.set_defaults(func=run)
