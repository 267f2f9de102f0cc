"""A full disk (a file-size limit on the command's process: tests/support/disk_limit.py) while a run
records or a report is written: one line naming the file, exit 1, no traceback; what is left
is readable (the recording up to its last complete chunk) or the previous file, untouched.
(The results table of a sweep: tests/e2e/studies/test_sweep.py.)"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from paths import REPO_ROOT

from hiyari.bridge.record.reader import Recording

LIMIT = REPO_ROOT / "tests" / "support" / "disk_limit.py"

# 4 s of a dart-out at 0.05 s, perfect perception: the recording passes 60 kB in its third
# second, every other file of the run stays below
DART_OUT = """
[scenario]
type = "dart-out"
seed = 3
duration = 4.0
step_length = 0.05
[ego]
perception = "perfect"
[parameters]
ve0_kmh = 30
ped_speed_kmh = 5
impact_fraction = 0.5
"""


def _limited(limit: int, *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, str(LIMIT), str(limit), *argv], capture_output=True, text=True, timeout=300
    )


def test_full_disk_while_recording_keeps_a_readable_part_file(tmp_path: Path) -> None:
    scen = tmp_path / "dart.toml"
    scen.write_text(DART_OUT)
    out = tmp_path / "run"
    proc = _limited(60_000, "run", str(scen), "-o", str(out), "-q")
    assert proc.returncode == 1, proc.stderr
    part = out / "run.mcap.part"
    assert proc.stderr.strip().splitlines() == [
        f"hiyari: error: {out / 'run.mcap'}: cannot write: File too large; {part} keeps the "
        "recording up to its last complete chunk"
    ]
    # nothing under a final name; the recording reads up to where the disk filled
    assert sorted(p.name for p in out.iterdir()) == ["run.mcap.part"]
    assert part.stat().st_size == 60_000
    rec = Recording.open(part)
    assert not rec.complete and 1.0 < rec.times[-1] < 4.0
    assert rec.world_and_ego(len(rec) - 1)[1] is not None


def test_full_disk_while_writing_a_report_keeps_the_previous_one(tmp_path: Path) -> None:
    report = tmp_path / "report.md"
    report.write_text("previous report\n")
    code = (
        "from hiyari.atomic import write_text_atomic\n"
        "from hiyari.errors import WriteFailed\n"
        "try:\n"
        f"    write_text_atomic({str(report)!r}, 'x' * 5000)\n"
        "except WriteFailed as exc:\n"
        "    print(exc)\n"
    )
    proc = _limited_code(4096, code)
    assert proc.stdout.strip() == (
        f"{report}: cannot write: File too large; report.md is left as it was"
    ), proc.stderr
    assert report.read_text() == "previous report\n"
    assert [p.name for p in tmp_path.iterdir()] == ["report.md"]  # no temporary left


def _limited_code(limit: int, code: str) -> subprocess.CompletedProcess[str]:
    """Python ``code`` in a child whose files are limited to ``limit`` bytes."""
    prologue = (
        "import resource, signal\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "hard = resource.getrlimit(resource.RLIMIT_FSIZE)[1]\n"
        f"resource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, hard))\n"
    )
    return subprocess.run(
        [sys.executable, "-c", prologue + code], capture_output=True, text=True, timeout=60
    )
