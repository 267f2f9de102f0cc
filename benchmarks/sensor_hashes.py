"""Hashes of the sensor closed loop's outputs, to show that a performance change changes none.

Five closed-loop runs with camera, radar and LiDAR (cut-in, cut-out, decel, dart-out and 8 s of
the city) hash every step's object lists (every field, array bytes included), fused tracks,
planner command and collisions; the 24 R157 judge rows of benchmarks/judge.py's sample
(sensors, 2 workers) are hashed row by row. One line per item, ``sha256  name``, written to
``--save`` and compared with ``--compare`` (exit 1 on a difference)::

    python benchmarks/sensor_hashes.py --save before.txt
    python benchmarks/sensor_hashes.py --save after.txt --compare before.txt

Run as a script by ``make bench`` it hashes and prints (nothing is compared).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from dataclasses import fields
from pathlib import Path

import numpy as np
from judge import mixed_points

from hiyari.bridge.loop.execute import execute
from hiyari.bridge.loop.stack.interfaces import EgoStep
from hiyari.bridge.loop.toml_runs import TomlRun
from hiyari.bridge.openscenario.presets.toml_file import ConcreteScenario
from hiyari.bridge.studies.r157_judge import JudgeOptions, judge
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.world_state import WorldState

#: (type, parameters, duration s, step s) of the five sensor runs.
RUNS = {
    "cut-in": (
        "cut-in",
        {"ve0_kmh": 60.0, "vo0_kmh": 30.0, "dx0_m": 25.0, "vy_ms": 1.0},
        10.0,
        0.05,
    ),
    "cut-out": ("cut-out", {"ve0_kmh": 60.0, "vy_ms": 1.5, "dx0_f_m": 30.0}, 10.0, 0.05),
    "decel": ("decel", {"ve0_kmh": 60.0, "gx_max_g": 0.6}, 10.0, 0.05),
    "dart-out": (
        "dart-out",
        {"ve0_kmh": 40.0, "ped_speed_kmh": 5.0, "impact_fraction": 0.5},
        10.0,
        0.05,
    ),
    "city": (
        "city",
        {
            "vehicles_per_hour": 2400.0,
            "persons_per_hour": 2400.0,
            "ve0_kmh": 40.0,
            "warmup_s": 300.0,
        },
        8.0,
        0.025,
    ),
}
JUDGE_POINTS = 24


def _update(h: hashlib._Hash, value: object) -> None:
    """Feed ``value`` (arrays by dtype, shape and bytes; object arrays by their repr)."""
    if isinstance(value, np.ndarray):
        h.update(f"{value.dtype}{value.shape}".encode())
        h.update(repr(value.tolist()).encode() if value.dtype == object else value.tobytes())
    else:
        h.update(repr(value).encode())


def _object_list(h: hashlib._Hash, ol: ObjectList) -> None:
    for f in fields(ol):
        h.update(f.name.encode())
        _update(h, getattr(ol, f.name))


def run_hash(name: str) -> tuple[str, int, float]:
    """sha256 of one sensor run's steps, the number of steps and its wall seconds."""
    stype, params, duration, step = RUNS[name]
    cs = ConcreteScenario(stype, f"hash {name}", 0, 1, duration, step, params, perception="sensors")
    h = hashlib.sha256()
    steps = 0

    def on_step(world: WorldState, ego: EgoStep, collisions: list) -> None:
        nonlocal steps
        steps += 1
        _update(h, world.time)
        for ol in ego.object_lists:
            _object_list(h, ol)
        _object_list(h, ego.tracks)
        for f in fields(ego.command):
            _update(h, getattr(ego.command, f.name))
        for c in collisions:
            _update(h, c)

    t0 = time.perf_counter()
    with TomlRun(cs).spec() as spec:
        res = execute(spec, on_step=on_step)
    wall = time.perf_counter() - t0
    _update(h, json.dumps(res.as_dict() | {"wall_seconds": None}, sort_keys=True, default=str))
    return h.hexdigest(), steps, wall


def judge_hashes() -> list[tuple[str, str]]:
    """(sha256, row name) of each of the judge sample's rows."""
    report = judge(mixed_points(JUDGE_POINTS), JudgeOptions(perception="sensors", workers=2), False)
    out = []
    for row in report.rows:
        blob = json.dumps(row, sort_keys=True, default=str).encode()
        out.append((hashlib.sha256(blob).hexdigest(), f"judge {row['id']} {row['condition']}"))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--save", type=Path, help="write the hashes here")
    ap.add_argument("--compare", type=Path, help="exit 1 unless equal to these hashes")
    ap.add_argument("--runs", default=",".join(RUNS), help="comma-separated sensor runs")
    ap.add_argument("--no-judge", action="store_true", help="leave the 24 judge rows out")
    args = ap.parse_args()
    lines = []
    for name in args.runs.split(","):
        digest, steps, wall = run_hash(name)
        print(f"{name}: {steps} steps, {wall:.1f} s wall", file=sys.stderr)
        lines.append(f"{digest}  run {name}")
    if not args.no_judge:
        t0 = time.perf_counter()
        lines += [f"{d}  {n}" for d, n in judge_hashes()]
        print(f"judge: {time.perf_counter() - t0:.1f} s wall", file=sys.stderr)
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if args.save:
        args.save.write_text(text)
    if args.compare:
        old = set(args.compare.read_text().splitlines())
        new = set(lines)
        diff = sorted((old ^ new), key=lambda s: s.split("  ", 1)[1])
        for line in diff:
            print(f"{'-' if line in old else '+'} {line}")
        print("identical" if not diff else f"{len(diff)} lines differ")
        if diff:
            raise SystemExit(1)


if __name__ == "__main__":
    main()
