"""Output-path mistakes (bridge.cli.outputs): a file where a folder is needed and the
reverse, a parent that is a file, a folder that cannot be written, an unknown cell: one line
naming the path and the problem, exit status 1, nothing created and nothing done first."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from hiyari.bridge.cli import status
from hiyari.bridge.cli.main import main

TOML = """
[scenario]
type = "cut-in"
duration = 1
step_length = 0.05
[ego]
perception = "none"
[parameters]
ve0_kmh = 60
vo0_kmh = 40
dx0_m = 30
vy_ms = 1.0
"""

# every command writing into an output folder, with what else it needs (FILE: a scenario)
FOLDER_COMMANDS = [
    ["run", "FILE"],
    ["sweep", "FILE"],
    ["evaluate"],
    ["boundary", "decel"],
    ["boundary", "cut-in"],
    ["perception", "coverage"],
    ["r157", "points"],
    ["r157", "judge", "points.json"],
    ["study", "sct"],
    ["sensors", "render"],
]


def _error(capsys) -> str:  # noqa: ANN001
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hiyari: error: "), err
    assert "Traceback" not in err[0]
    return err[0].removeprefix("hiyari: error: ")


def _listing(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    path = tmp_path / "cut_in.toml"
    path.write_text(TOML)
    return path


@pytest.mark.parametrize("command", FOLDER_COMMANDS, ids=lambda c: " ".join(c))
def test_a_file_where_a_folder_is_needed(tmp_path: Path, capsys, scenario: Path, command) -> None:  # noqa: ANN001
    target = tmp_path / "taken"
    target.write_text("someone's file")
    before = _listing(tmp_path)
    argv = [str(scenario) if a == "FILE" else a for a in command]
    assert main([*argv, "-o", str(target)]) == status.ERROR
    assert _error(capsys) == f"-o {target}: is a file, not a folder"
    assert target.read_text() == "someone's file" and _listing(tmp_path) == before


def test_a_parent_that_is_a_file(tmp_path: Path, capsys, scenario: Path) -> None:  # noqa: ANN001
    (tmp_path / "taken").write_text("x")
    target = tmp_path / "taken" / "runs" / "one"
    assert main(["run", str(scenario), "-o", str(target)]) == status.ERROR
    assert _error(capsys) == f"-o {target}: {tmp_path / 'taken'} is a file, not a folder"


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere")
def test_a_folder_that_cannot_be_written(tmp_path: Path, capsys, scenario: Path) -> None:  # noqa: ANN001
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    try:
        assert main(["run", str(scenario), "-o", str(locked / "out")]) == status.ERROR
        assert (
            _error(capsys) == f"-o {locked / 'out'}: cannot write in {locked} (permission denied)"
        )
    finally:
        locked.chmod(0o755)


def test_unknown_cell_creates_nothing(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    out = tmp_path / "eval"
    assert main(["evaluate", "--cells", "M99", "-o", str(out)]) == status.ERROR
    assert _error(capsys) == "--cells M99: no evaluated cell matches"
    assert not out.exists()


def test_replay_export_to_a_folder_is_refused_before_the_export(
    tmp_path: Path, capsys, scenario: Path
) -> None:  # noqa: ANN001
    run = tmp_path / "run"
    assert main(["run", str(scenario), "-q", "-o", str(run)]) == status.OK
    capsys.readouterr()
    folder = tmp_path / "replays"
    folder.mkdir()
    rec = str(run / "run.mcap")
    assert main(["replay", rec, "--export", str(folder), "-q"]) == status.ERROR
    assert _error(capsys) == f"--export {folder}: is a folder, give a file name"
    assert list(folder.iterdir()) == []  # no export written beside, no temporary left
    assert main(["replay", rec, "--recover", str(folder)]) == status.ERROR
    assert _error(capsys) == f"--recover {folder}: is a folder, give a file name"
