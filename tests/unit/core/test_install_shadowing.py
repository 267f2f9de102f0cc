"""The installed package wins over a folder named ``hiyari`` beside a script: a user who
cloned into ``~/hiyari`` and runs a script from ``~`` imports hiyari, not the clone folder as
an empty namespace package (the Makefile's install puts the editable finder first)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import hiyari


def test_a_folder_named_hiyari_beside_the_script_does_not_shadow_the_package(
    tmp_path: Path,
) -> None:
    (tmp_path / "hiyari").mkdir()
    (tmp_path / "hiyari" / "README.md").write_text("a clone's root has no __init__.py\n")
    script = tmp_path / "script.py"
    script.write_text(
        "import hiyari, hiyari.units\nprint(hiyari.__file__)\nprint(hiyari.units.__name__)\n"
    )
    done = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    package_file, units = done.stdout.split()
    assert Path(package_file).resolve() == Path(hiyari.__file__).resolve()
    assert units == "hiyari.units"
