"""`hiyari run` records its run (run.mcap, on by default for one run, --no-record to skip);
a run killed with SIGKILL mid-recording leaves a .part file that reads up to its last
complete chunk and recovers into a finished trace."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from osi_utilities import MultiTraceReader

from hiyari.bridge.cli.main import main
from hiyari.bridge.record.reader import Recording
from hiyari.errors import HiyariError

CUT_IN = """
[scenario]
type = "cut-in"
duration = {duration}
step_length = 0.05
[parameters]
ve0_kmh = 60
vo0_kmh = {vo0}
dx0_m = 30
vy_ms = 1.0
"""


def _scenario(tmp_path: Path, duration: float = 4.0, vo0: str = "40") -> Path:
    p = tmp_path / f"cut_in_{duration:g}.toml"
    p.write_text(CUT_IN.format(duration=duration, vo0=vo0))
    return p


def test_single_run_is_recorded_by_default(tmp_path, capsys):
    out = tmp_path / "rec"
    assert main(["run", str(_scenario(tmp_path)), "-o", str(out), "-q"]) == 0
    assert "recorded:" in capsys.readouterr().out
    rec = Recording.open(out / "run.mcap")
    assert rec.complete and rec.problem is None
    assert len(rec) == 80  # 4 s at 0.05 s
    np.testing.assert_allclose(np.diff(rec.times), 0.05, atol=1e-9)
    assert rec.metadata["scenario"].startswith("cut-in#0")
    assert "fusion" in rec.object_sources
    assert len(rec.road().lane) > 0  # the road of the run's net is in the trace
    world, ego = rec.world_and_ego(len(rec) - 1)
    assert ego is not None and ego in world.ids


def test_no_record_and_grids(tmp_path):
    scen = _scenario(tmp_path)
    assert main(["run", str(scen), "-o", str(tmp_path / "plain"), "-q", "--no-record"]) == 0
    assert (tmp_path / "plain" / "result.json").is_file()
    assert not list((tmp_path / "plain").glob("run.mcap*"))
    grid = tmp_path / "grid.toml"
    grid.write_text(CUT_IN.format(duration=2.0, vo0="{ values = [30, 40] }"))
    assert main(["run", str(grid), "-o", str(tmp_path / "g"), "-q"]) == 0
    assert not list((tmp_path / "g").rglob("run.mcap"))  # a grid records only when asked
    assert main(["run", str(grid), "-o", str(tmp_path / "g2"), "-q", "--record"]) == 0
    assert len(list((tmp_path / "g2").rglob("run.mcap"))) == 2


def test_run_killed_mid_recording_reads_up_to_last_chunk(tmp_path):
    scen = _scenario(tmp_path, duration=300.0)
    out = tmp_path / "killed"
    proc = subprocess.Popen(
        [sys.executable, "-m", "hiyari", "run", str(scen), "-o", str(out), "-q"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env={**os.environ, "TMPDIR": str(tmp_path)},  # SIGKILL leaves temporary folders
    )
    part = out / "run.mcap.part"
    frames = 0
    deadline = time.time() + 180
    try:
        while time.time() < deadline and frames < 200 and proc.poll() is None:
            time.sleep(0.2)
            try:
                frames = len(Recording.open(part))
            except HiyariError:  # not created yet, or no complete chunk yet
                frames = 0
        os.kill(proc.pid, signal.SIGKILL)  # kill -9: no handler, no clean-up
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL and frames >= 200
    assert not (out / "run.mcap").exists()
    rec = Recording.open(part)
    assert not rec.complete and "incomplete" in rec.problem
    assert len(rec) >= frames  # everything seen before the kill is still there
    np.testing.assert_allclose(np.diff(rec.times), 0.05, atol=1e-9)
    assert rec.world(len(rec) - 1).time == pytest.approx(rec.times[-1])
    # the finished copy opens in the OSI readers, road included
    fixed = tmp_path / "fixed.mcap"
    assert main(["replay", str(part), "--recover", str(fixed)]) == 0
    reader = MultiTraceReader()
    assert reader.open(fixed)
    reader.set_topics(["/osi/ground_truth"])
    gts = [r.message for r in reader]
    reader.close()
    assert len(gts) == len(rec) and len(gts[0].lane) > 0
