"""Many independent runs in worker processes: a local process pool (fork) or a Ray cluster,
with interrupts that stop cleanly.

libsumo allows one simulation per process, so every many-run job (sweeps, the R157 judge,
the SCT study) hands its runs to :func:`run_all`, which yields ``(task index, result)`` as
runs finish.

Interrupts: workers ignore Ctrl-C (SIGINT reaches the whole process group); the parent, on
Ctrl-C, SIGTERM (the CLI turns it into KeyboardInterrupt) or any error, cancels the runs not
started and sends SIGTERM to its workers, which raise SystemExit inside the run they are in:
every ``with`` and ``finally`` unwinds (SUMO closed, temporary folders removed, unfinished
outputs discarded) and the worker exits without a traceback. Then the exception goes on to
the caller, which keeps what finished (a sweep's rows) and says how to resume.

Progress: a run may call :func:`report_progress` (e.g. simulated seconds done); the amounts
reach the ``on_progress`` callback of :func:`run_all` in the parent as they happen (local
backend; on Ray only finished runs count).
"""

from __future__ import annotations

import multiprocessing
import os
import shutil
import signal
import tempfile
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from typing import Any, TypeVar

from hiyari.errors import HiyariError

T = TypeVar("T")
R = TypeVar("R")

BACKENDS = ("local", "ray")
#: Seconds a worker gets to unwind after SIGTERM before it is killed.
STOP_GRACE_S = 20.0


@dataclass(frozen=True)
class PoolOptions:
    """``workers`` local processes (1: run in this process), or a Ray cluster at
    ``ray_address`` ("auto" joins a running cluster; None starts a local one with ``workers``
    CPUs)."""

    workers: int = max(1, os.cpu_count() or 1)
    backend: str = "local"
    ray_address: str | None = None

    def validate(self) -> None:
        """Raise HiyariError for an unknown backend or a worker count below 1."""
        if self.backend not in BACKENDS:
            raise HiyariError(f"unknown backend {self.backend!r} ({' or '.join(BACKENDS)})")
        if self.workers < 1:
            raise HiyariError(f"--workers must be >= 1, got {self.workers}")


# Where report_progress sends amounts: set in a worker by its initializer, or around a run in
# this process. Process-local by construction (one value per process).
_progress_sink: Callable[[float], None] | None = None


def report_progress(amount: float) -> None:
    """Called from inside a run: add ``amount`` to the caller's progress (no-op when nobody
    listens)."""
    if _progress_sink is not None:
        _progress_sink(amount)


def run_all(
    fn: Callable[[T], R],
    tasks: Sequence[T],
    options: PoolOptions,
    on_progress: Callable[[float], None] | None = None,
) -> Iterator[tuple[int, R]]:
    """Run ``fn(task)`` for every task (submitted in order); yield ``(index, result)`` as
    runs finish. ``fn`` must be a module-level function (it is sent to the workers).

    An exception raised by a run stops the pool and is raised here; so is an interrupt.
    """
    options.validate()
    if not tasks:
        return
    if options.backend == "ray":
        yield from _run_ray(fn, tasks, options)
    elif options.workers == 1 or len(tasks) == 1:
        yield from _run_here(fn, tasks, on_progress)
    else:
        yield from _run_local(fn, tasks, options.workers, on_progress)


def _run_here(
    fn: Callable[[T], R], tasks: Sequence[T], on_progress: Callable[[float], None] | None
) -> Iterator[tuple[int, R]]:
    global _progress_sink
    for i, task in enumerate(tasks):
        previous, _progress_sink = _progress_sink, on_progress
        try:
            result = fn(task)
        finally:
            _progress_sink = previous
        yield i, result


def _init_worker(queue: Any, temp_root: str) -> None:
    global _progress_sink
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides what Ctrl-C does
    signal.signal(signal.SIGTERM, _exit_worker)
    _progress_sink = queue.put if queue is not None else None
    # A SIGTERM can land between mkdtemp and the ``with`` that would remove the folder, or
    # inside rmtree: workers' temporary files go under one root the parent removes at the end.
    tempfile.tempdir = temp_root
    os.environ["TMPDIR"] = temp_root


def _exit_worker(signum: int, frame: object) -> None:
    # SystemExit unwinds the run (with / finally) and ends the process without a traceback
    raise SystemExit(128 + signum)


def _run_local(
    fn: Callable[[T], R],
    tasks: Sequence[T],
    workers: int,
    on_progress: Callable[[float], None] | None,
) -> Iterator[tuple[int, R]]:
    # fork: workers start at once with everything imported; no simulation is open here
    ctx = multiprocessing.get_context("fork")
    queue = ctx.SimpleQueue() if on_progress is not None else None
    temp_root = tempfile.mkdtemp(prefix="hiyari-pool-")
    pool = ProcessPoolExecutor(
        max_workers=min(workers, len(tasks)),
        mp_context=ctx,
        initializer=_init_worker,
        initargs=(queue, temp_root),
    )

    def drain() -> None:
        while queue is not None and not queue.empty():
            on_progress(queue.get())

    try:
        index = {pool.submit(fn, task): i for i, task in enumerate(tasks)}
        pending = set(index)
        while pending:
            finished, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            drain()
            for fut in finished:
                yield index[fut], fut.result()
        drain()
    except BrokenProcessPool:
        _stop(pool)
        raise HiyariError(
            "a worker process died (killed from outside, or out of memory); the runs that "
            "finished are kept"
        ) from None
    except BaseException:
        _stop(pool)
        raise
    else:
        pool.shutdown(wait=True)
    finally:
        shutil.rmtree(temp_root, ignore_errors=True)


def _stop(pool: ProcessPoolExecutor) -> None:
    """Cancel what has not started and end the workers (SIGTERM, then SIGKILL after the
    grace time)."""
    # concurrent.futures has no public way to end busy workers before Python 3.14
    processes = list((pool._processes or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        if p.is_alive():
            p.terminate()
    for p in processes:
        p.join(STOP_GRACE_S)
        if p.is_alive():
            p.kill()
            p.join()


def _run_ray(
    fn: Callable[[T], R], tasks: Sequence[T], options: PoolOptions
) -> Iterator[tuple[int, R]]:
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
    pending: list = []
    try:
        remote = ray.remote(num_cpus=1)(fn)
        index = {remote.remote(task): i for i, task in enumerate(tasks)}
        pending = list(index)
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            for ref in ready:
                try:
                    result = ray.get(ref)
                except ray.exceptions.RayTaskError as exc:
                    raise exc.as_instanceof_cause() from None
                yield index[ref], result
    except BaseException:
        for ref in pending:  # a KeyboardInterrupt inside each run: it unwinds and cleans up
            ray.cancel(ref)
        if pending:
            ray.wait(pending, num_returns=len(pending), timeout=STOP_GRACE_S)
        raise
    finally:
        if started:
            ray.shutdown()
