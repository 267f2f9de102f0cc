"""Interrupted runs (Ctrl-C to the process group, as a terminal sends it; SIGTERM) never leave
a cut-short output under its final name, and the same command run again redoes them; failed
runs leave no ``.part`` or road folder behind. Real subprocesses on real scenarios."""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from hiyari.bridge.cli import status
from hiyari.bridge.cli.main import main
from hiyari.bridge.record.reader import Recording
from hiyari.errors import HiyariError

# two lead-braking runs an ego without perception hits: both are recorded after the campaign
EVALUATE = ["evaluate", "--cells", "M02-front-2L", "--runs-per-cell", "2", "--perception", "none"]


def _start(args: list[str], tmp: Path) -> subprocess.Popen:
    """``hiyari ARGS`` in its own process group, its temporary folders in ``tmp``, with Ctrl-C
    enabled as in a terminal's foreground job (an ignored SIGINT would stay ignored across
    exec when the tests run in the background: see test_sweep._start_sweep)."""
    tmp.mkdir(exist_ok=True)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        return subprocess.Popen(
            [sys.executable, "-m", "hiyari", *args],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
            env={**os.environ, "TMPDIR": str(tmp)},
        )
    finally:
        signal.signal(signal.SIGINT, previous)


def _when_written(proc: subprocess.Popen, folder: Path, pattern: str, timeout: float = 120) -> Path:
    """The first file matching ``pattern`` in ``folder`` once it has content."""
    deadline = time.time() + timeout
    while time.time() < deadline and proc.poll() is None:
        found = [p for p in folder.glob(pattern) if p.stat().st_size > 0]
        if found:
            return found[0]
        time.sleep(0.02)
    proc.kill()
    raise AssertionError(f"no {pattern} in {folder}: {proc.communicate()[1]}")


@pytest.mark.slow
def test_interrupted_evaluate_keeps_no_cut_short_recording(tmp_path: Path) -> None:
    """The failed runs are recorded by two workers (the default uses every core); they ignore
    the Ctrl-C and are stopped by the campaign, inside the recorded run."""
    out = tmp_path / "eval"
    argv = [*EVALUATE, "-j", "2", "-q", "-o", str(out)]
    proc = _start(argv, tmp_path / "tmp")
    part = _when_written(proc, out / "recordings", "*.mcap.part")
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == status.INTERRUPTED, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert "run the same command again to record them" in err
    assert not list((out / "recordings").glob("*.mcap")), "a cut-short recording got its name"
    assert list((tmp_path / "tmp").iterdir()) == []
    # the same command again: the campaign's rows are done, the recordings are redone whole
    assert main([*argv]) == status.VERDICT_FAIL
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [r["passed"] for r in rows] == ["False", "False"]
    for r in rows:
        rec = Recording.open(out / "recordings" / f"{r['run_id']}.mcap")
        assert rec.complete and rec.problem is None
        # the recording reaches the contact the results row reports
        assert rec.times[-1] >= float(r["collision_time_s"]) - 1e-6
    assert not list((out / "recordings").glob("*.part")), part


def _cut_in(tmp_path: Path, duration: float, stack: str = "") -> Path:
    scen = tmp_path / f"cut_in_{duration:g}.toml"
    scen.write_text(
        f'[scenario]\ntype = "cut-in"\nduration = {duration}\nstep_length = 0.05\n'
        f"[ego]\n{stack}\n"
        "[parameters]\nve0_kmh = 60\nvo0_kmh = 40\ndx0_m = 30\nvy_ms = 1.0\n"
    )
    return scen


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_run_writes_nothing_under_a_final_name(tmp_path: Path, sig: int) -> None:
    out = tmp_path / "run"
    proc = _start(["run", str(_cut_in(tmp_path, 300.0)), "-q", "-o", str(out)], tmp_path / "tmp")
    part = _when_written(proc, out, "run.mcap.part")
    frames, deadline = 0, time.time() + 120
    while frames < 20 and time.time() < deadline and proc.poll() is None:
        time.sleep(0.1)
        try:
            frames = len(Recording.open(part))
        except HiyariError:  # no complete chunk yet
            frames = 0
    if sig == signal.SIGINT:
        os.killpg(proc.pid, sig)  # as a terminal sends Ctrl-C
    else:
        os.kill(proc.pid, sig)
    _, err = proc.communicate(timeout=60)
    expected = status.INTERRUPTED if sig == signal.SIGINT else status.TERMINATED
    assert proc.returncode == expected, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert f"{part} holds its recording so far" in err
    # the recording keeps its unfinished name; nothing else of the run is left
    assert sorted(p.name for p in out.iterdir()) == ["run.mcap.part"]
    rec = Recording.open(part)
    assert not rec.complete and len(rec) >= frames >= 20  # readable up to the interrupt
    assert list((tmp_path / "tmp").iterdir()) == []


EXPLODING = """
from hiyari.bridge.loop.spec import default_stack
from hiyari.errors import HiyariError


class Exploding:
    \"\"\"The default stack, failing 1 s into the run (after the recording has begun).\"\"\"

    def __init__(self, ctx):
        inner = default_stack(ctx)
        self.perception, self.fusion, self.planner = inner.perception, inner.fusion, inner.planner
        self._inner = inner

    def step(self, world, row):
        if world.time > 1.0:
            raise HiyariError("planner diverged")
        return self._inner.step(world, row)
"""


def test_failed_run_leaves_no_part_or_roads(tmp_path: Path, monkeypatch, capsys) -> None:  # noqa: ANN001
    (tmp_path / "exploding_stack.py").write_text(EXPLODING)
    monkeypatch.syspath_prepend(str(tmp_path))
    scen = _cut_in(tmp_path, 4.0, 'stack = "exploding_stack:Exploding"')
    out = tmp_path / "out"
    assert main(["run", str(scen), "-q", "-o", str(out)]) == status.ERROR
    assert capsys.readouterr().err.strip() == "hiyari: error: " + f"{scen}: planner diverged"
    assert not out.exists()  # the run made it: no .part, no roads/, no empty folder
    # a folder the user had keeps what was there before
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert main(["run", str(scen), "-q", "-o", str(out)]) == status.ERROR
    assert [p.name for p in out.iterdir()] == ["notes.txt"]
