"""``hiyari evaluate``: run the JAMA traffic-disturbance catalogue against an ego stack and
write the safety-argument report (HTML + Markdown + PNGs); resumable."""

from __future__ import annotations

import argparse
import os
import shlex
import sys
import time
from pathlib import Path

from hiyari.bridge.cli import numbers, status
from hiyari.bridge.cli.outputs import output_folder


def evaluate(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from hiyari.bridge.studies.catalogue.evaluation.campaign import (
        CatalogueOptions,
        catalogue_cells,
        run_catalogue,
    )
    from hiyari.bridge.studies.catalogue.evaluation.provenance import run_configuration
    from hiyari.bridge.studies.catalogue.evaluation.runner import RunConfig
    from hiyari.bridge.studies.catalogue.structures import ensure_coverage
    from hiyari.bridge.studies.pool import PoolOptions
    from hiyari.bridge.studies.report.catalogue import write_report

    out = output_folder(args.out)
    if args.structures:
        output_folder(args.structures, "--structures")
    if args.export:
        from hiyari.bridge.studies.catalogue.evaluation.campaign import case_by_id
        from hiyari.bridge.studies.catalogue.space.xosc_export import export_case

        for run_id in args.export.split(","):
            case = case_by_id(run_id, args.catalogue, args.seed)
            print(f"scenario: {export_case(case, out / 'roads', out / 'xosc')}")
        return 0
    config = RunConfig(
        roads=out / "roads", perception=args.perception, stack=args.stack or "",
        step_length=args.step,
    )  # fmt: skip
    options = CatalogueOptions(
        run=config,
        catalogue=args.catalogue,
        runs_per_cell=args.runs_per_cell,
        seed=args.seed,
        pool=PoolOptions(args.workers, args.backend, args.ray_address, args.in_process),
        only=tuple(k for k in (args.cells or "").split(",") if k),
    )
    t0 = time.perf_counter()
    bars: list[tqdm] = []  # made at the first progress: a refused selection prints no bar

    def progress(done: int, total: int) -> None:
        if not bars:
            bars.append(tqdm(total=total, unit="run", disable=args.quiet, desc="catalogue"))
        bars[0].total = total
        bars[0].n = done
        bars[0].refresh()

    try:
        rows = run_catalogue(options, out, progress)
    finally:
        for bar in bars:
            bar.close()
    wall = time.perf_counter() - t0
    cells = catalogue_cells(args.catalogue, options.ranges)
    structures = ensure_coverage(Path(args.structures) if args.structures else out / "structures")
    command = shlex.join(["hiyari", *args.argv])
    run_conf = run_configuration(options, command, wall, structures)
    html = write_report(out, cells, rows, run_conf, options.ranges, structures)
    n_pass = sum(r["passed"] == "True" for r in rows)
    crashed = sum(r["passed"] == "crashed" for r in rows)
    untested = sum(r["passed"] == "not tested" for r in rows)
    near = sum(int(r.get("near_misses") or 0) for r in rows)
    false = sum(int(r.get("false_activations") or 0) for r in rows)
    print(
        f"{len(rows)} runs, {n_pass} passed, {len(rows) - n_pass - crashed - untested} failed, "
        f"{crashed} crashed, {untested} not tested; {near} near misses, {false} false "
        f"activations; {wall:.1f} s wall"
    )
    print(f"report: {html}")
    if crashed:
        print(
            f"hiyari: {crashed} run(s) crashed (their worker process died; see the report's "
            "failures); run the same command again to retry them",
            file=sys.stderr,
        )
    return status.verdict(n_pass == len(rows), crashed)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "evaluate",
        help="run the JAMA traffic-disturbance catalogue and write the safety-argument report",
        description="Runs the catalogue's concrete cases, judges each against the C&C driver "
        "and writes the report; exit status 3 when a run did not pass, 4 when a run "
        "crashed (rerun to retry it).",
    )
    p.add_argument("--catalogue", choices=["motorway", "general"], default="motorway")
    p.add_argument("--stack", default=None,
                   help="ego stack factory 'module:callable' taking a StackContext "
                        "(default: hiyari's stack)")  # fmt: skip
    p.add_argument("--perception", choices=["perfect", "sensors", "none"], default="perfect")
    p.add_argument("--runs-per-cell", type=numbers.count(1, 100_000), default=14,
                   help="concrete runs per evaluated cell (default: 14)")  # fmt: skip
    p.add_argument("--cells", default="",
                   help="only these cells: comma-separated key prefixes, e.g. M03,M02-front")  # fmt: skip
    p.add_argument("--seed", type=numbers.seed(), default=0, help="seed of the sampling")
    p.add_argument("--step", type=numbers.seconds(), default=0.1,
                   help="simulation step, s (default 0.1)")  # fmt: skip
    p.add_argument("-o", "--out", required=True, help="output folder (resumable)")
    p.add_argument("--workers", "-j", type=numbers.count(1, 4096), default=os.cpu_count() or 1,
                   help="local worker processes (default: all cores)")  # fmt: skip
    p.add_argument("--backend", choices=["local", "ray"], default="local")
    p.add_argument("--ray-address", default=None, help="Ray cluster: 'auto' or host:port")
    p.add_argument("--in-process", action="store_true",
                   help="run the runs one after the other in this process, not in worker "
                        "processes (a native crash then ends the campaign)")  # fmt: skip
    p.add_argument("--export", default="",
                   help="write these cases (comma-separated run ids, e.g. M03-left_rear-2L-004) "
                        "as OpenSCENARIO + OpenDRIVE into OUT/xosc and run nothing")  # fmt: skip
    p.add_argument("--structures", default=None,
                   help="folder of the 'hiyari perception coverage / sweep / blindspots / grip' "
                        "pages to include (default: OUT/structures, where the coverage is "
                        "written when missing)")  # fmt: skip
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=evaluate)
