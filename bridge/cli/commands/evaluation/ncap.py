"""``hiyari ncap -o DIR``: the Euro NCAP 2023 AEB Car-to-Car and VRU grids run against an ego
stack, scored, and written as a datasheet (HTML + PNG); resumable."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from hiyari.bridge.cli import numbers, status
from hiyari.bridge.cli.outputs import output_folder


def _speeds(text: str) -> tuple[float, ...]:
    from hiyari.errors import HiyariError

    try:
        return tuple(float(s) for s in text.split(",") if s.strip())
    except ValueError:
        raise HiyariError(f"--speeds: expected km/h values like 20,40, got {text!r}") from None


def ncap(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from hiyari.bridge.studies.ncap.protocols import default_root
    from hiyari.bridge.studies.ncap.study import NcapOptions, run_study
    from hiyari.bridge.studies.pool import PoolOptions
    from hiyari.bridge.studies.report.ncap.page import write_report

    out = output_folder(args.out)
    options = NcapOptions(
        out_dir=out,
        protocol=args.protocol,
        perception=args.perception,
        environment=args.environment,
        stack=args.stack or "",
        files=Path(args.files) if args.files else default_root(),
        only=tuple(k for k in args.tests.split(",") if k),
        speeds=_speeds(args.speeds),
        step_length=args.step,
        pool=PoolOptions(args.workers, args.backend, args.ray_address),
        replays=not args.no_replays,
    )
    bars: list[tqdm] = []

    def progress(done: int, total: int) -> None:
        if not bars:
            bars.append(tqdm(total=total, unit="run", disable=args.quiet, desc="ncap"))
        bars[0].n = done
        bars[0].refresh()

    t0 = time.perf_counter()
    try:
        result = run_study(options, progress)
    finally:
        for bar in bars:
            bar.close()
    wall = time.perf_counter() - t0
    config = {
        "command": " ".join(["hiyari", *sys.argv[1:]]),
        "stack": args.stack or "hiyari NCAP stack (perception -> Kalman fusion -> AEB, ACC off)",
        "perception": args.perception,
        "day environment": args.environment,
        "Euro NCAP files": str(options.files),
        "reduced grid": (f"tests {args.tests or 'all'}, speeds {args.speeds or 'all'}"
                         if args.tests or args.speeds else "no: the protocols' full grids"),
        "workers / backend": f"{args.workers} / {args.backend}",
        "test points run now / kept from before": f"{result.ran} / {result.kept}",
        "wall time of this invocation (s)": f"{wall:.1f}",
    }  # fmt: skip
    html = write_report(out, result, config)
    for p in result.protocols:
        print(f"{p.protocol.upper()}: {p.points:.2f} of {p.max_points:.2f} points "
              f"({p.percent:.1f} %)")  # fmt: skip
    lost = sum(s.colour is not None and s.colour.value != "green" for s in result.points.values())
    untested = sum(s.colour is None for s in result.points.values())
    from hiyari.bridge.studies.ncap.study import activation_counts

    near, false = activation_counts(result.rows.values())
    print(f"{len(result.points)} test points: {lost} lost points, {untested} not tested; "
          f"{near} near misses, {false} false activations; {wall:.1f} s wall")  # fmt: skip
    print(f"report: {html}")
    return status.verdict(lost == 0 and untested == 0)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "ncap",
        help="run the Euro NCAP 2023 AEB Car-to-Car and VRU grids, score them, write the datasheet",
        description="Runs every test point of the Euro NCAP 2023 AEB C2C and VRU protocols' "
        "grids (Vector's OpenSCENARIO files), or the 2026 CA-FC Standard Range grids, scores "
        "them and writes the datasheet; exit "
        "status 3 when a test point lost points or could not be tested.",
    )
    p.add_argument("-o", "--out", required=True, help="output folder (resumable)")
    p.add_argument("--protocol", choices=["c2c", "vru", "all", "ca2026"], default="all",
                   help="all: the 2023 C2C and VRU protocols; ca2026: the 2026 Crash "
                        "Avoidance - Frontal Collisions Standard Range (Vector's CA-FC_2026 "
                        "folder under --files)")  # fmt: skip
    p.add_argument("--perception", choices=["perfect", "sensors"], default="perfect")
    p.add_argument("--environment", default="clear",
                   help="disturbance preset of the day tests; night tests run at night with "
                        "low beams (night_headlights)")  # fmt: skip
    p.add_argument("--stack", default=None,
                   help="ego stack factory 'module:callable' taking a StackContext "
                        "(default: hiyari's stack with ACC off)")  # fmt: skip
    p.add_argument("--files", default=None,
                   help="the Euro NCAP set's root (holding OpenSCENARIO/NCAP; default: "
                        "$HIYARI_NCAP_DIR, else ../shared/data/openscenario/ncap)")  # fmt: skip
    p.add_argument("--tests", default="",
                   help="only these tests, e.g. CCRs,CPNA-25 (a reduced grid)")  # fmt: skip
    p.add_argument("--speeds", default="",
                   help="only these test speeds, km/h, e.g. 20,40 (a reduced grid)")  # fmt: skip
    p.add_argument("--step", type=numbers.seconds(), default=0.05,
                   help="simulation step, s")  # fmt: skip
    p.add_argument("--workers", "-j", type=numbers.count(1, 4096), default=os.cpu_count() or 1,
                   help="local worker processes (default: all cores)")  # fmt: skip
    p.add_argument("--backend", choices=["local", "ray"], default="local")
    p.add_argument("--ray-address", default=None, help="Ray cluster: 'auto' or host:port")
    p.add_argument("--no-replays", action="store_true",
                   help="record the points that lost points but export no replay page")  # fmt: skip
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=ncap)
