"""Sweeps: same table on 1 worker, 2 workers and Ray; resumable after a kill; failures kept."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from paths import REPO_ROOT

from hiyari.bridge.loop.toml_runs import TomlPlan
from hiyari.bridge.openscenario.presets.toml_file import load_scenario
from hiyari.bridge.studies.report.sweep import plot_sweep
from hiyari.bridge.studies.sweep import SweepOptions, read_table, run_sweep
from hiyari.errors import HiyariError

GRID = """
[scenario]
type = "dart-out"
name = "dart-out speed sweep"
seed = 100
duration = 10.0
step_length = 0.1
[ego]
perception = "perfect"
{stack}
[parameters]
ve0_kmh = {{ range = [20, 69], step = 12 }}
ped_speed_kmh = 5
impact_fraction = 0.5
"""


def _scenario(tmp_path: Path, stack: str = "") -> Path:
    p = tmp_path / "sweep.toml"
    p.write_text(GRID.format(stack=stack))
    return p


def _errors(table: Path) -> dict[int, str]:
    """The error column of a sweep table's rows that are not ok (a failed assert shows why)."""
    return {
        i: f"{r['status']}: {r['error']}"
        for i, r in read_table(table).items()
        if r["status"] != "ok"
    }


def _plan(path: Path) -> TomlPlan:
    return TomlPlan(load_scenario(path))


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The grid's 5 runs (20, 32, 44, 56 and 68 km/h) on 1 worker: the table every other
    sweep here is compared with, byte for byte (whole or its first rows)."""
    tmp = tmp_path_factory.mktemp("ref")
    s = run_sweep(_plan(_scenario(tmp)), SweepOptions(tmp / "w1", workers=1, progress=False))
    assert s.total == 5 and s.ran == 5 and s.failed == 0, _errors(s.table)
    return s.table.read_bytes()


def test_two_workers_same_table(reference, tmp_path):
    s = run_sweep(
        _plan(_scenario(tmp_path)), SweepOptions(tmp_path / "w2", workers=2, progress=False)
    )
    assert s.table.read_bytes() == reference
    rows = read_table(s.table)
    # the sweep covers both outcomes: slow runs stop short, fast ones cannot (68 km/h)
    collisions = [r["collision"] for r in rows.values()]
    assert "True" in collisions and "False" in collisions
    png = plot_sweep("grid", ["ve0_kmh"], list(rows.values()), tmp_path / "summary.png")
    assert png.stat().st_size > 1000


def test_ray_local_cluster_same_table(reference, tmp_path):
    """The reference's first 3 runs (seeds and parameters by run index) on a local Ray
    cluster: the same bytes as the header and first 3 rows of the in-process table. (Starting
    the cluster and its workers is most of the cost; 3 runs on 2 Ray workers still exercise
    the out-of-order completion the table writer must put back in order.)"""
    pytest.importorskip("ray")
    scen = _scenario(tmp_path)
    scen.write_text(scen.read_text().replace("range = [20, 69]", "range = [20, 45]"))
    s = run_sweep(
        _plan(scen), SweepOptions(tmp_path / "ray", backend="ray", workers=2, progress=False)
    )
    assert s.total == 3 and s.ran == 3 and s.failed == 0
    assert s.table.read_bytes() == b"".join(reference.splitlines(True)[:4])


def _start_sweep(scen: Path, out: Path, tmp: Path, workers: int) -> subprocess.Popen:
    """`hiyari sweep` in its own process group, its temporary folders in ``tmp``, with
    Ctrl-C enabled as in a terminal's foreground job.

    A test run started in the background by a shell without job control (``make test &`` in a
    script, some CI runners) has SIGINT ignored, and an ignored signal stays ignored across
    exec: the sweep would ignore the Ctrl-C and finish with status 0. A handled signal is reset
    to its default across exec, so SIGINT is handled here while the process starts."""
    tmp.mkdir(exist_ok=True)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        return subprocess.Popen(
            [sys.executable, "-m", "hiyari", "sweep", str(scen), "-o", str(out)]
            + ["-j", str(workers), "-q"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
            env={**os.environ, "TMPDIR": str(tmp)},
        )
    finally:
        signal.signal(signal.SIGINT, previous)


def test_killed_sweep_resumes_only_missing_rows(reference, tmp_path):
    """The reference's 5 runs, killed (SIGKILL) after the 2nd row: the same command again
    runs only the missing runs and the table is the reference's, byte for byte."""
    scen = _scenario(tmp_path)
    out = tmp_path / "killed"
    # SIGKILL leaves the run's temporary folders: they go to a folder of this test
    proc = _start_sweep(scen, out, tmp_path / "tmp", workers=1)
    table = out / "results.csv"
    deadline = time.time() + 120
    while time.time() < deadline and len(read_table(table)) < 2:
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    before = len(read_table(table))
    assert 2 <= before < 5
    s = run_sweep(_plan(scen), SweepOptions(out, workers=1, progress=False))
    assert s.total == 5 and s.skipped == before and s.ran == 5 - before
    assert table.read_bytes() == reference


def test_failing_run_is_recorded(reference, tmp_path, monkeypatch):
    """The reference's first 3 runs with a stack that raises in run 1 (32 km/h) on 2 workers:
    run 1 is a failed row with the error, the others are ok and the reference's rows."""
    # a module name of its own: test_cli_interrupt imports another exploding_stack in this process
    mod = tmp_path / "exploding_sweep_stack.py"
    mod.write_text(
        "from hiyari.bridge.loop.spec import default_stack\n"
        "def Exploding(ctx):\n"
        "    if round(ctx.set_speed * 3.6, 6) == 32:\n"
        "        raise RuntimeError('planner diverged at 32 km/h')\n"
        "    return default_stack(ctx)\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    scen = _scenario(tmp_path, stack='stack = "exploding_sweep_stack:Exploding"')
    scen.write_text(scen.read_text().replace("range = [20, 69]", "range = [20, 45]"))
    s = run_sweep(_plan(scen), SweepOptions(tmp_path / "fail", workers=2, progress=False))
    rows = read_table(s.table)
    assert s.failed == 1 and len(rows) == 3
    bad = [r for r in rows.values() if r["status"] == "failed"]
    assert [r["ve0_kmh"] for r in bad] == ["32.0"]
    assert bad[0]["error"] == "RuntimeError: planner diverged at 32 km/h"
    assert all(r["status"] == "ok" for r in rows.values() if r["ve0_kmh"] != "32.0")
    ref_path = tmp_path / "reference.csv"
    ref_path.write_bytes(reference)
    ref = read_table(ref_path)
    assert all(rows[i] == ref[i] for i in (0, 2))


@pytest.mark.parametrize("sig, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupted_sweep_stops_cleanly(reference, tmp_path, sig, status):
    """Ctrl-C (to the whole process group, as a terminal sends it) or SIGTERM: the workers
    stop, no traceback, the rows done are kept, the message says how to resume, and no
    temporary folder is left (resuming is tested after a SIGKILL above)."""
    scen = _scenario(tmp_path)
    out, tmp = tmp_path / "stopped", tmp_path / "tmp"
    proc = _start_sweep(scen, out, tmp, workers=2)
    table = out / "results.csv"
    deadline = time.time() + 120
    while time.time() < deadline and len(read_table(table)) < 2:
        time.sleep(0.1)
    if sig == signal.SIGINT:
        os.killpg(proc.pid, sig)
    else:
        os.kill(proc.pid, sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == status, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "run the same command again to resume" in lines[0], err
    kept = len(read_table(table))
    assert 2 <= kept < 5 and f"{kept} of 5 runs are kept" in lines[0]
    assert list(tmp.iterdir()) == []
    # the rows kept are whole and the same as in the uninterrupted sweep
    ref_path = tmp_path / "reference.csv"
    ref_path.write_bytes(reference)
    ref = read_table(ref_path)
    assert all(row == ref[i] for i, row in read_table(table).items())


def test_run_count_guard_counts_without_expanding(tmp_path, capsys):
    from hiyari.bridge.cli.main import main

    scen = tmp_path / "tiny.toml"
    scen.write_text(
        GRID.format(stack="").replace("step = 12 }", "step = 1e-7 }")
        + "[sampling]\nmode = 'grid'\n"
    )
    t0 = time.process_time()  # CPU, not wall: a loaded machine must not fail the check
    status = main(["sweep", str(scen), "-o", str(tmp_path / "out"), "-q"])
    err = capsys.readouterr().err
    assert status == 1, err
    assert f"{scen}: the parameter ranges give 490,000,001 runs" in err
    assert "--max-runs 10,000" in err
    assert time.process_time() - t0 < 2.0  # counted, not listed
    assert not (tmp_path / "out").exists()
    # the grid of the other tests is counted exactly (5 runs) against a lowered limit
    logical = _plan(_scenario(tmp_path))
    with pytest.raises(HiyariError, match="give 5 runs, more than --max-runs 4"):
        run_sweep(logical, SweepOptions(tmp_path / "o2", max_runs=4, progress=False))


def test_crashed_run_is_recorded_then_retried(reference, tmp_path, monkeypatch, capsys):
    """A worker killed by SIGSEGV in the middle of run 2 (the test-only hook) of a 4-run sweep
    (the reference's first 4): the other runs finish, run 2 is recorded as crashed with its
    seed, parameters and the signal, the command exits RUNS_CRASHED; the same command again
    runs only run 2, and the table is the uninterrupted sweep's byte for byte."""
    from hiyari.bridge.cli import status
    from hiyari.bridge.cli.main import main
    from hiyari.bridge.studies.pool import TEST_CRASH_ENV

    scen = _scenario(tmp_path)
    scen.write_text(scen.read_text().replace("range = [20, 69]", "range = [20, 57]"))
    out = tmp_path / "crash"
    argv = ["sweep", str(scen), "-o", str(out), "-j", "2", "-q"]
    monkeypatch.setenv(TEST_CRASH_ENV, "2")
    assert main(argv) == status.RUNS_CRASHED
    printed = capsys.readouterr()
    assert "4 runs: 4 ran now, 0 already done, 0 failed, 1 crashed" in printed.out
    assert "1 run(s) crashed" in printed.err and "run the same command again" in printed.err
    rows = read_table(out / "results.csv")
    assert sorted(rows) == [0, 1, 2, 3]
    assert [i for i, r in rows.items() if r["status"] != "ok"] == [2]
    ref_path = tmp_path / "reference.csv"
    ref_path.write_bytes(reference)
    ref = read_table(ref_path)
    crashed = rows[2]
    assert (crashed["seed"], crashed["ve0_kmh"]) == (ref[2]["seed"], ref[2]["ve0_kmh"])
    assert (crashed["seed"], crashed["ve0_kmh"]) == ("102", "44.0")
    assert crashed["status"] == "crashed"
    assert crashed["error"] == "worker process died of SIGSEGV (signal 11)"
    assert crashed["collision"] == ""
    assert all(rows[i] == ref[i] for i in (0, 1, 3))
    # the rerun retries the crashed run only (the hook stays set: there is no task 2 of 1)
    assert main(argv) == status.OK, _errors(out / "results.csv")
    assert "4 runs: 1 ran now, 3 already done, 0 failed, 0 crashed" in capsys.readouterr().out
    assert (out / "results.csv").read_bytes() == b"".join(reference.splitlines(True)[:5])


def test_full_disk_stops_the_sweep_keeping_the_rows_done(reference, tmp_path):
    """The results table cannot grow past its third row (a file-size limit on the sweep's
    process, as a full disk): one line naming the table, exit 1, the two rows done kept whole
    (the cut third one is skipped), nothing else touched; the same command with room again
    finishes the sweep and the table is the uninterrupted one's byte for byte."""
    scen = _scenario(tmp_path)
    scen.write_text(scen.read_text().replace("range = [20, 69]", "range = [20, 57]"))
    out = tmp_path / "full"
    lines = reference.splitlines(True)
    limit = len(b"".join(lines[:3])) + 10  # the header, two rows and 10 bytes of the third
    argv = ["sweep", str(scen), "-o", str(out), "-j", "1", "-q"]
    proc = subprocess.run(
        [sys.executable, str(REPO_ROOT / "tests" / "support" / "disk_limit.py"), str(limit), *argv],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    table = out / "results.csv"
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        f"hiyari: error: {table}: cannot write: File too large; 2 of 4 runs are kept in "
        f"{table}; run the same command again to resume"
    ]
    assert table.read_bytes() == b"".join(lines[:3]) + lines[3][:10]
    assert sorted(read_table(table)) == [0, 1]
    assert sorted(p.name for p in out.iterdir()) == ["results.csv", "timings.csv"]
    from hiyari.bridge.cli.main import main

    assert main(argv) == 0, _errors(table)
    assert table.read_bytes() == b"".join(lines[:5])
