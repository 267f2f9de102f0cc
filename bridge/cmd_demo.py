"""``hiyari demo``: the main jobs on built-in defaults, then where the outputs are."""

from __future__ import annotations

import argparse
from pathlib import Path

from hiyari.bridge.demo_traffic import run_traffic_demo


def run(args: argparse.Namespace) -> int:
    out = Path(args.out)
    print(f"== traffic: signalised city intersection, {args.duration:.0f} s simulated")
    d = run_traffic_demo(out / "traffic", duration=args.duration, seed=args.seed)
    print(
        f"   {d['vehicles_seen']} vehicles and {d['persons_seen']} pedestrians, "
        f"{d['steps_per_second']:.0f} steps/s ({d['realtime_factor']:.0f}x real time), "
        f"{len(d['collision_pairs'])} collision pairs"
    )
    print(f"\noutputs in {out.resolve()}:")
    for f in sorted(p for p in out.rglob("*") if p.is_file()):
        print(f"   {f.relative_to(out)}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="run the main jobs on built-in defaults")
    p.add_argument("--out", default="out/demo", help="output folder")
    p.add_argument("--duration", type=float, default=300.0, help="traffic seconds to simulate")
    p.add_argument("--seed", type=int, default=42)
    p.set_defaults(func=run)
