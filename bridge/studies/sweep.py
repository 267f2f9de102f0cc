"""Scenario sweeps: every concrete run of a scenario file (a TOML logical scenario, or an
OpenSCENARIO parameter distribution), each in its own worker process.

libsumo runs one simulation per process, so runs go to the campaign pool
(:mod:`hiyari.bridge.studies.pool`): local worker processes (default) or a Ray cluster
(``backend="ray"``; ``pip install hiyari[ray]``). Runs are independent and seeded by their
index, so the result table is the same whichever backend or worker count ran them.
Results stream to ``results.csv`` as runs finish (one row per run, flushed), so a killed sweep
resumes where it stopped: a re-run skips the rows already there. An interrupted sweep (Ctrl-C,
SIGTERM) stops its workers, keeps the rows done and says how to resume. A run whose worker
process dies (a native crash in SUMO or a sensor library, an out-of-memory kill) is recorded
with ``status = "crashed"`` and the signal in ``error``; the other runs go on, and a re-run
retries the crashed rows (failed ones only with ``retry_failed``: they are deterministic). At the end the table
is rewritten sorted by run index; wall-clock timings go to ``timings.csv`` so that
``results.csv`` is reproducible byte for byte.

The number of runs is counted from the ranges before anything is expanded, and a sweep of
more than ``max_runs`` runs is refused (a typo in a step can otherwise ask for millions).
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

from hiyari.atomic import append_bytes, atomic_path
from hiyari.bridge.loop.result import RESULT_KEYS
from hiyari.bridge.loop.spec import Plan, PlannedRun, SkippedRun
from hiyari.bridge.studies.pool import Crashed, PoolOptions, run_all
from hiyari.errors import HiyariError, WriteFailed


@dataclass(frozen=True)
class SweepOptions:
    """Where and how to run. ``workers`` local processes, or a Ray cluster at ``ray_address``
    ("auto" joins a running cluster; None starts a local one)."""

    out_dir: Path
    backend: str = "local"  # "local" or "ray"
    workers: int = max(1, (os.cpu_count() or 1))
    ray_address: str | None = None
    retry_failed: bool = False
    progress: bool = True
    max_runs: int = 10_000  # refuse sweeps with more runs than this
    in_process: bool = False  # runs one after the other in this process (a crash ends all)

    def pool(self) -> PoolOptions:
        """The pool these options ask for."""
        return PoolOptions(self.workers, self.backend, self.ray_address, self.in_process)


@dataclass
class SweepSummary:
    """Counts of one sweep call (runs skipped were already in the table; ``failed`` and
    ``crashed`` count the table's rows with that status)."""

    total: int
    ran: int
    skipped: int
    failed: int
    wall_seconds: float
    table: Path
    crashed: int = 0
    constraint: int = 0  # runs not executed: their parameters break the constraints


def run_one(run: PlannedRun) -> tuple[dict, float]:
    """Run one concrete run; never raises: failures become a row with the error."""
    from hiyari.bridge.loop.execute import execute

    t0 = time.perf_counter()
    row: dict = {"index": run.index, "seed": run.seed, **run.params}
    try:
        with run.spec() as spec:
            res = execute(spec)
        row.update(status="ok", error="", **res.row())
    except Exception as exc:  # one failing run must not stop the sweep
        msg = " ".join(f"{type(exc).__name__}: {exc}".split())
        row.update(status="failed", error=msg, **dict.fromkeys(RESULT_KEYS, ""))
    return row, time.perf_counter() - t0


def crashed_row(run: PlannedRun, crash: Crashed) -> dict:
    """The row of a run whose worker process died: its seed and parameters, and the signal."""
    return {
        "index": run.index,
        "seed": run.seed,
        **run.params,
        "status": "crashed",
        "error": str(crash),
        **dict.fromkeys(RESULT_KEYS, ""),
    }


def skipped_row(run: SkippedRun) -> dict:
    """The row of a run not executed (its parameters break the scenario's constraints)."""
    return {
        "index": run.index,
        "seed": run.seed,
        **run.params,
        "status": "skipped",
        "error": f"constraint: {run.reason}",
        **dict.fromkeys(RESULT_KEYS, ""),
    }


def _columns(plan: Plan) -> list[str]:
    return ["index", "seed", *plan.parameter_names, "status", "error", *RESULT_KEYS]


def read_table(path: Path) -> dict[int, dict]:
    """Rows of an existing results.csv by run index (a torn last line is ignored)."""
    if not path.exists():
        return {}
    rows = {}
    with path.open(newline="") as f:
        reader = csv.DictReader(f)
        for row in reader:
            if None in row or any(v is None for v in row.values()) or not row.get("status"):
                continue  # a row cut short when the sweep was killed
            rows[int(row["index"])] = row
    return rows


def _fmt(v: object) -> str:
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ""
    return "" if v is None else str(v)


def run_sweep(plan: Plan, options: SweepOptions) -> SweepSummary:
    """Run every concrete run not yet in ``out_dir/results.csv``; return counts. A road the
    runs share (an OpenSCENARIO file's) is made once into ``out_dir/roads``."""
    from tqdm import tqdm

    options.pool().validate()
    n = plan.count()
    if n > options.max_runs:
        raise HiyariError(
            f"{plan.path}: the parameter ranges give {n:,} runs, more than --max-runs "
            f"{options.max_runs:,} (use coarser steps, or raise --max-runs)"
        )
    existed = options.out_dir.exists()
    try:
        plan = plan.with_roads(options.out_dir / "roads")
        runs = plan.expand()
        if not runs:
            raise HiyariError(f"{plan.path}: the parameters expand to no run")
    except BaseException:
        if not existed:  # refused before any run: nothing of this sweep is left
            shutil.rmtree(options.out_dir, ignore_errors=True)
        raise
    out = options.out_dir
    out.mkdir(parents=True, exist_ok=True)
    table = out / "results.csv"
    cols = _columns(plan)
    done = read_table(table)
    if done and list(next(iter(done.values()))) != cols:
        raise HiyariError(f"{table}: columns differ from this scenario's; use another folder")
    # crashed runs are always run again; failed ones (deterministic) only when asked
    retry = {"crashed", "failed"} if options.retry_failed else {"crashed"}
    # the skipped runs' rows are written anew each time (their reason is the plan's)
    skips = {r.index: {k: _fmt(v) for k, v in skipped_row(r).items()} for r in plan.skipped}
    keep = {i: r for i, r in done.items() if r["status"] not in retry and i not in skips}
    todo = [run for run in runs if run.index not in keep]
    t0 = time.perf_counter()
    failed = sum(r["status"] == "failed" for r in keep.values())
    crashed = 0
    # rewrite the kept rows (drops torn lines), then append as runs finish
    _write_rows(
        table, cols, sorted([*keep.values(), *skips.values()], key=lambda r: int(r["index"]))
    )
    timings = out / "timings.csv"
    with (
        tqdm(
            total=len(runs),
            initial=len(keep),
            unit="run",
            disable=not options.progress,
            desc="sweep",
        ) as bar,
        contextlib.closing(run_all(run_one, todo, options.pool())) as results,
    ):
        try:
            for i, result in results:
                if isinstance(result, Crashed):
                    row = crashed_row(todo[i], result)
                    crashed += 1
                else:
                    row, wall = result
                    append_bytes(timings, f"{row['index']},{wall:.4f}\n".encode())
                append_bytes(table, _csv_line(cols, {k: _fmt(row.get(k)) for k in cols}))
                failed += row["status"] == "failed"
                bar.update(1)
                bar.set_postfix(failed=failed, crashed=crashed, remaining=len(runs) - bar.n)
        except (KeyboardInterrupt, WriteFailed) as exc:  # Ctrl-C, SIGTERM or a full disk
            results.close()  # the workers stop
            resume = (
                f"{len(read_table(table))} of {len(runs)} runs are kept in {table}; run the "
                "same command again to resume"
            )
            if isinstance(exc, WriteFailed):
                raise WriteFailed(f"{exc}; {resume}") from None
            exc.args = (resume,)
            raise
    final = read_table(table)
    _write_rows(table, cols, [final[i] for i in sorted(final)])
    summary = SweepSummary(
        len(runs), len(todo), len(keep), failed, time.perf_counter() - t0, table, crashed,
        len(skips),
    )  # fmt: skip
    return summary


def _csv_line(cols: list[str], row: dict) -> bytes:
    buf = io.StringIO()
    csv.DictWriter(buf, fieldnames=cols).writerow(row)
    return buf.getvalue().encode()


def _write_rows(path: Path, cols: list[str], rows: list[dict]) -> None:
    with atomic_path(path) as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in cols})
