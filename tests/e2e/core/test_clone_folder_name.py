"""A clone in a folder named ``hiyari`` beside a user's script (the default of ``git clone``)
makes ``import hiyari`` a namespace package over the clone, which skips
``hiyari/__init__.py``: the CLI and the package's modules must work all the same."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from paths import REPO_ROOT

SCRIPT = """
from hiyari.bridge.loop.spec import EgoSetup
from hiyari.bridge.studies.catalogue.evaluation.provenance import git_commit
from hiyari.kinematics import Pose
from hiyari.version import __version__
print(__version__, git_commit()[:7], EgoSetup().perception)
"""


def test_a_clone_folder_named_hiyari_does_not_break_scripts_beside_it(tmp_path: Path) -> None:
    (tmp_path / "hiyari").symlink_to(REPO_ROOT, target_is_directory=True)
    (tmp_path / "s.py").write_text(SCRIPT)
    run = subprocess.run([sys.executable, "s.py"], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    version, commit, perception = run.stdout.split()
    assert perception == "perfect" and len(commit) == 7
    cli = subprocess.run([sys.executable, "-m", "hiyari", "--version"], cwd=tmp_path,
                         capture_output=True, text=True)  # fmt: skip
    assert cli.returncode == 0 and cli.stdout.strip() == f"hiyari {version}", cli.stderr
