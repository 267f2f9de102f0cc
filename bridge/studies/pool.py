"""Many independent runs in worker processes: a local process pool (fork) or a Ray cluster,
with interrupts that stop cleanly and native crashes that lose one run, never the campaign.

libsumo allows one simulation per process, and a native crash in it (or in any library a run
loads) ends the process: so every many-run job (sweeps, evaluate, the R157 judge, the SCT
study, the blind-spot catalogue) hands its runs to :func:`run_all`, which runs them in worker
processes and yields ``(task index, result)`` as runs finish. Running them in this process is
an explicit option (``PoolOptions(in_process=True)``: a crash then ends everything).

Crashes: a worker that dies while running a task (segfault, abort, out-of-memory kill, or any
exit without a result) yields that task's :class:`Crashed` (the signal that ended it) in
place of its result, and a new worker takes over the remaining tasks. The caller records the
run as crashed and counts it; a rerun retries it. Workers run with :mod:`faulthandler` on, so
a native crash leaves the Python stack of the run on stderr.

Interrupts: workers ignore Ctrl-C (SIGINT reaches the whole process group); the parent, on
Ctrl-C, SIGTERM (the CLI turns it into KeyboardInterrupt) or any error, stops its workers
(SIGTERM), which raise SystemExit inside the run they are in: every ``with`` and ``finally``
unwinds (SUMO closed, temporary folders removed, unfinished outputs discarded) and the worker
exits without a traceback. Then the exception goes on to the caller, which keeps what finished
(a sweep's rows) and says how to resume.

Progress: a run may call :func:`report_progress` (e.g. simulated seconds done); the amounts
reach the ``on_progress`` callback of :func:`run_all` in the parent as they happen (local
backend; on Ray only finished runs count).
"""

from __future__ import annotations

import faulthandler
import multiprocessing
import os
import resource
import shutil
import signal
import tempfile
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from typing import Any, TypeVar

from hiyari.errors import HiyariError

T = TypeVar("T")
R = TypeVar("R")

BACKENDS = ("local", "ray")
#: Seconds a worker gets to unwind after SIGTERM before it is killed.
STOP_GRACE_S = 20.0
#: Test-only hook: the worker running task ``N`` (its position in ``run_all``'s tasks) kills
#: itself with SIGSEGV 0.2 s into the run (or as it ends, if sooner), as a native crash would.
TEST_CRASH_ENV = "HIYARI_TEST_CRASH_RUN"


@dataclass(frozen=True)
class PoolOptions:
    """``workers`` local worker processes, or a Ray cluster at ``ray_address`` ("auto" joins
    a running cluster; None starts a local one with ``workers`` CPUs). ``in_process``: run
    every task in this process, one after the other (no protection from native crashes)."""

    workers: int = max(1, os.cpu_count() or 1)
    backend: str = "local"
    ray_address: str | None = None
    in_process: bool = False

    def validate(self) -> None:
        """Raise HiyariError for an unknown backend or a worker count below 1."""
        if self.backend not in BACKENDS:
            raise HiyariError(f"unknown backend {self.backend!r} ({' or '.join(BACKENDS)})")
        if self.workers < 1:
            raise HiyariError(f"--workers must be >= 1, got {self.workers}")


@dataclass(frozen=True)
class Crashed:
    """What :func:`run_all` yields for a task whose worker process died before returning its
    result. ``signal``: the signal that ended the worker (None: unknown, or a plain exit)."""

    reason: str
    signal: int | None = None

    @classmethod
    def from_exitcode(cls, exitcode: int | None) -> Crashed:
        """From a process's exit code (negative: killed by that signal)."""
        if exitcode is not None and exitcode < 0:
            try:
                name = signal.Signals(-exitcode).name
            except ValueError:
                name = f"signal {-exitcode}"
            return cls(f"worker process died of {name} (signal {-exitcode})", -exitcode)
        return cls(f"worker process exited with status {exitcode} before the run ended")

    def __str__(self) -> str:
        return self.reason


# Where report_progress sends amounts: set in a worker when it starts, or around a run in
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
) -> Iterator[tuple[int, R | Crashed]]:
    """Run ``fn(task)`` for every task (started in order); yield ``(index, result)`` as runs
    finish, with a :class:`Crashed` as the result of a run whose worker died. ``fn`` must be
    a module-level function (Ray sends it to its workers).

    An exception raised by a run stops the pool and is raised here; so is an interrupt.
    """
    options.validate()
    if not tasks:
        return
    if options.in_process:
        yield from _run_here(fn, tasks, on_progress)
    elif options.backend == "ray":
        yield from _run_ray(fn, tasks, options)
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


def _call(fn: Callable[[T], R], index: int, task: T) -> R:
    """``fn(task)`` in a worker, with the test-only crash hook for task ``index``."""
    if os.environ.get(TEST_CRASH_ENV) != str(index):
        return fn(task)

    def crash(*_: object) -> None:
        # no core file: a deliberate crash is no evidence, and its core is hundreds of MB
        resource.setrlimit(resource.RLIMIT_CORE, (0, resource.getrlimit(resource.RLIMIT_CORE)[1]))
        os.kill(os.getpid(), signal.SIGSEGV)

    signal.signal(signal.SIGALRM, crash)
    signal.setitimer(signal.ITIMER_REAL, 0.2)
    result = fn(task)
    crash()
    return result


def _worker(conn: Connection, fn: Callable[[Any], Any], temp_root: str) -> None:
    """A worker's life: run the tasks the parent sends until it sends None."""
    global _progress_sink
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides what Ctrl-C does
    signal.signal(signal.SIGTERM, _exit_worker)
    # a native crash prints the run's Python stack (on the descriptor: sys.stderr may be a
    # stream without one, as under pytest's capture)
    faulthandler.enable(file=2)
    # A SIGTERM can land between mkdtemp and the ``with`` that would remove the folder, or
    # inside rmtree: workers' temporary files go under one root the parent removes at the end.
    tempfile.tempdir = temp_root
    os.environ["TMPDIR"] = temp_root
    _progress_sink = lambda amount: conn.send(("progress", amount))  # noqa: E731
    while True:
        try:
            job = conn.recv()
        except EOFError:  # the parent is gone
            return
        if job is None:
            return
        index, task = job
        try:
            message = ("done", index, _call(fn, index, task))
        except Exception as exc:  # the parent raises it
            message = ("error", index, exc)
        try:
            conn.send(message)
        except Exception as exc:  # a result or an exception that cannot be pickled
            conn.send(("error", index, HiyariError(f"{type(exc).__name__}: {exc}")))


def _exit_worker(signum: int, frame: object) -> None:
    # SystemExit unwinds the run (with / finally) and ends the process without a traceback
    raise SystemExit(128 + signum)


@dataclass
class _Worker:
    process: Any  # multiprocessing's fork Process
    conn: Connection
    job: int | None = None  # index of the task it runs


def _run_local(
    fn: Callable[[T], R],
    tasks: Sequence[T],
    workers: int,
    on_progress: Callable[[float], None] | None,
) -> Iterator[tuple[int, R | Crashed]]:
    # fork: workers start at once with everything imported; no simulation is open here
    ctx = multiprocessing.get_context("fork")
    temp_root = tempfile.mkdtemp(prefix="hiyari-pool-")
    todo = deque(range(len(tasks)))
    pool: list[_Worker] = []
    try:
        while todo or any(w.job is not None for w in pool):
            while len(pool) < min(workers, len(tasks)) and todo:  # start, or replace the dead
                parent, child = ctx.Pipe()
                # not a daemon: a run may start processes of its own
                process = ctx.Process(target=_worker, args=(child, fn, temp_root))
                process.start()
                child.close()
                pool.append(_Worker(process, parent))
            for w in pool:
                if w.job is None and todo:
                    _hand(w, todo, tasks)
            wait([w.conn for w in pool] + [w.process.sentinel for w in pool])
            for w in list(pool):
                yield from _collect(w, pool, on_progress)
        for w in pool:
            w.conn.send(None)
        for w in pool:
            w.process.join(STOP_GRACE_S)
    except BaseException:
        _stop([w.process for w in pool])
        raise
    finally:
        for w in pool:
            w.conn.close()
        shutil.rmtree(temp_root, ignore_errors=True)


def _hand(w: _Worker, todo: deque[int], tasks: Sequence[Any]) -> None:
    """Send the next task to idle worker ``w`` (back to ``todo`` if ``w`` died idle)."""
    w.job = todo.popleft()
    try:
        w.conn.send((w.job, tasks[w.job]))
    except (BrokenPipeError, ConnectionResetError):  # not its run's fault: it is replaced
        todo.appendleft(w.job)
        w.job = None


def _collect(
    w: _Worker, pool: list[_Worker], on_progress: Callable[[float], None] | None
) -> Iterator[tuple[int, Any]]:
    """Yield what worker ``w`` finished (a result, or Crashed if it died in a run); pass on
    its progress; raise the exception of a run that raised; drop ``w`` from ``pool`` if dead."""
    alive = w.process.is_alive()  # before reading: a result sent, then an exit, is a result
    for kind, index, value in _messages(w):
        if kind == "progress":
            if on_progress is not None:
                on_progress(value)
        elif kind == "error":
            raise value
        else:
            w.job = None
            yield index, value
    if not alive:
        w.process.join()
        w.conn.close()
        pool.remove(w)
        if w.job is not None:
            yield w.job, Crashed.from_exitcode(w.process.exitcode)


def _messages(w: _Worker) -> Iterator[tuple[str, int | None, Any]]:
    """What worker ``w`` has sent so far, as (kind, task index, value); stops at its end."""
    while True:
        try:
            if not w.conn.poll():
                return
            message = w.conn.recv()
        except (EOFError, OSError):  # the worker is gone (a message cut short counts as none)
            return
        if message[0] == "progress":
            yield "progress", None, message[1]
        else:
            yield message


def _stop(processes: list[Any]) -> None:
    """End the workers: SIGTERM (they unwind the run they are in), then SIGKILL after the
    grace time."""
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
) -> Iterator[tuple[int, R | Crashed]]:
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
        # no retry: a run that crashed its worker is reported, as on the local backend
        remote = ray.remote(num_cpus=1, max_retries=0)(_call)
        index = {remote.remote(fn, i, task): i for i, task in enumerate(tasks)}
        pending = list(index)
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            for ref in ready:
                try:
                    result = ray.get(ref)
                except ray.exceptions.RayTaskError as exc:
                    raise exc.as_instanceof_cause() from None
                except (ray.exceptions.WorkerCrashedError, ray.exceptions.OutOfMemoryError):
                    result = Crashed("Ray worker process died (native crash or out of memory)")
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
