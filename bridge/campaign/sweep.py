"""Scenario sweeps: every concrete run of a logical scenario, each in its own worker process.

libsumo runs one simulation per process, so runs go to a local process pool (default) or to a
Ray cluster (``backend="ray"``; ``pip install hiyari[ray]``). Runs are independent and seeded
by their index, so the result table is the same whichever backend or worker count ran them.
Results stream to ``results.csv`` as runs finish (one row per run, flushed), so a killed sweep
resumes where it stopped: a re-run skips the rows already there. At the end the table is
rewritten sorted by run index; wall-clock timings go to ``timings.csv`` so that ``results.csv``
is reproducible byte for byte.
"""

from __future__ import annotations

import csv
import math
import multiprocessing
import os
import time
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path

from hiyari.atomic import atomic_path
from hiyari.bridge.scenario.result import RESULT_KEYS
from hiyari.bridge.scenario.toml_file import ConcreteScenario, LogicalScenario
from hiyari.errors import HiyariError


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


@dataclass
class SweepSummary:
    """Counts of one sweep call (runs skipped were already in the table)."""

    total: int
    ran: int
    skipped: int
    failed: int
    wall_seconds: float
    table: Path


def run_one(cs: ConcreteScenario) -> tuple[dict, float]:
    """Run one concrete scenario; never raises: failures become a row with the error."""
    from hiyari.bridge.scenario.run import run_concrete

    t0 = time.perf_counter()
    row: dict = {"index": cs.index, "seed": cs.seed, **cs.params}
    try:
        row.update(status="ok", error="", **run_concrete(cs).row())
    except Exception as exc:  # one failing run must not stop the sweep
        msg = " ".join(f"{type(exc).__name__}: {exc}".split())
        row.update(status="failed", error=msg, **dict.fromkeys(RESULT_KEYS, ""))
    return row, time.perf_counter() - t0


def _columns(logical: LogicalScenario) -> list[str]:
    from hiyari.bridge.scenario.toml_file import PARAMETERS

    return ["index", "seed", *PARAMETERS[logical.type], "status", "error", *RESULT_KEYS]


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


def run_sweep(logical: LogicalScenario, options: SweepOptions) -> SweepSummary:
    """Run every concrete scenario not yet in ``out_dir/results.csv``; return counts."""
    from tqdm import tqdm

    runs = logical.expand()
    if not runs:
        raise HiyariError(f"{logical.path}: the parameters expand to no run")
    if options.backend not in ("local", "ray"):
        raise HiyariError(f"unknown backend {options.backend!r} (local or ray)")
    if options.workers < 1:
        raise HiyariError(f"--workers must be >= 1, got {options.workers}")
    out = options.out_dir
    out.mkdir(parents=True, exist_ok=True)
    table = out / "results.csv"
    cols = _columns(logical)
    done = read_table(table)
    if done and list(next(iter(done.values()))) != cols:
        raise HiyariError(f"{table}: columns differ from this scenario's; use another folder")
    keep = {i: r for i, r in done.items() if r["status"] == "ok" or not options.retry_failed}
    todo = [cs for cs in runs if cs.index not in keep]
    t0 = time.perf_counter()
    failed = sum(r["status"] == "failed" for r in keep.values())
    # rewrite the kept rows (drops torn lines), then append as runs finish
    _write_rows(table, cols, sorted(keep.values(), key=lambda r: int(r["index"])))
    timings = out / "timings.csv"
    with (
        table.open("a", newline="") as f,
        timings.open("a") as tf,
        tqdm(
            total=len(runs),
            initial=len(keep),
            unit="run",
            disable=not options.progress,
            desc="sweep",
        ) as bar,
    ):
        writer = csv.DictWriter(f, fieldnames=cols)
        for row, wall in execute_runs(todo, options):
            writer.writerow({k: _fmt(row.get(k)) for k in cols})
            f.flush()
            tf.write(f"{row['index']},{wall:.4f}\n")
            tf.flush()
            failed += row["status"] == "failed"
            bar.update(1)
            bar.set_postfix(failed=failed, remaining=len(runs) - bar.n)
    final = read_table(table)
    _write_rows(table, cols, [final[i] for i in sorted(final)])
    summary = SweepSummary(len(runs), len(todo), len(keep), failed, time.perf_counter() - t0, table)
    plot_sweep(logical, [final[i] for i in sorted(final)], out / "summary.png")
    return summary


def _write_rows(path: Path, cols: list[str], rows: list[dict]) -> None:
    with atomic_path(path) as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in cols})


def execute_runs(
    todo: list[ConcreteScenario], options: SweepOptions
) -> Iterator[tuple[dict, float]]:
    """Run concrete scenarios on the configured backend; yield (row, wall s) as they finish."""
    if not todo:
        return
    if options.backend == "ray":
        yield from _execute_ray(todo, options)
        return
    if options.workers == 1:
        for cs in todo:
            yield run_one(cs)
        return
    # fork is safe: no simulation is open in this process, and each run starts its own
    ctx = multiprocessing.get_context("fork")
    with ProcessPoolExecutor(max_workers=options.workers, mp_context=ctx) as pool:
        pending = {pool.submit(run_one, cs) for cs in todo}
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                yield fut.result()


def _execute_ray(
    todo: list[ConcreteScenario], options: SweepOptions
) -> Iterator[tuple[dict, float]]:
    try:
        import ray
    except ImportError:
        raise HiyariError("the ray backend needs Ray: pip install 'hiyari[ray]'") from None
    started = not ray.is_initialized()
    if started:
        kwargs = (
            {"address": options.ray_address}
            if options.ray_address
            else {"num_cpus": options.workers}
        )
        ray.init(include_dashboard=False, log_to_driver=False, **kwargs)
    try:
        remote = ray.remote(num_cpus=1)(run_one)
        pending = [remote.remote(cs) for cs in todo]
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            for ref in ready:
                yield ray.get(ref)
    finally:
        if started:
            ray.shutdown()


def plot_sweep(logical: LogicalScenario, rows: list[dict], out: Path) -> Path | None:
    """Outcome over the first two varied parameters (or one), collision vs no collision."""
    from matplotlib.figure import Figure

    varied = [k for k in (*logical.ranges, *logical.random)]
    ok = [r for r in rows if r["status"] == "ok"]
    if not ok or not varied:
        return None
    xk = varied[0]
    yk = varied[1] if len(varied) > 1 else "min_ttc_s"
    fig = Figure(figsize=(7, 5))
    ax = fig.subplots()
    for coll, color, label in (
        ("True", "tab:red", "collision"),
        ("False", "tab:green", "no collision"),
    ):
        pts = [(float(r[xk]), float(r[yk])) for r in ok if r["collision"] == coll and r[yk] != ""]
        if pts:
            ax.scatter(*zip(*pts, strict=True), c=color, label=label, s=25, edgecolors="k", lw=0.3)
    failed = [r for r in rows if r["status"] == "failed"]
    ax.set_xlabel(xk)
    ax.set_ylabel(yk)
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title(
        f"{logical.name}: {len(ok)} runs, {sum(r['collision'] == 'True' for r in ok)} "
        f"collisions, {len(failed)} failed"
    )
    fig.tight_layout()
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return out
