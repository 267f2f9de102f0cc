"""Cost of ``hiyari ncap``'s full grids: for each protocol, the number of test points, the
wall time on this machine with ``-j`` workers, runs/s, and next to them the bare run time
(the runs' own wall seconds summed, without pool, recording of the points that lost points,
replays and report).

    .venv/bin/python benchmarks/ncap.py [--perception perfect|sensors] [-j 2] [--out DIR]

Resumable like the command (the same --out skips the points done); a fresh --out measures.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from hiyari.bridge.studies.ncap.study import NcapOptions, run_study
from hiyari.bridge.studies.pool import PoolOptions
from hiyari.bridge.studies.report.ncap.page import write_report


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--perception", choices=["perfect", "sensors"], default="perfect")
    ap.add_argument("-j", "--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--protocol", choices=["c2c", "vru", "all"], default="all")
    ap.add_argument("--out", default="out/bench-ncap")
    args = ap.parse_args()
    protocols = ["c2c", "vru"] if args.protocol == "all" else [args.protocol]
    print("protocol  points  ran  wall_s  runs_per_s  bare_run_s  score")
    for name in protocols:
        out = Path(args.out) / f"{name}-{args.perception}"
        options = NcapOptions(out, protocol=name, perception=args.perception,
                              pool=PoolOptions(args.workers))  # fmt: skip
        t0 = time.perf_counter()
        res = run_study(options)
        write_report(out, res, {"command": "benchmarks/ncap.py"})
        wall = time.perf_counter() - t0
        bare = sum(float(r["wall_seconds"] or 0) for r in res.rows.values())
        score = res.protocols[0]
        print(f"{name:8}  {len(res.rows):6}  {res.ran:3}  {wall:6.0f}  "
              f"{res.ran / wall if res.ran else 0:10.2f}  {bare:10.0f}  "
              f"{score.points:.2f}/{score.max_points:.2f} ({score.percent:.1f} %)")  # fmt: skip


if __name__ == "__main__":
    main()
