"""The shared data of a checkout is found beside it, or beside the checkout it was cloned from
(a clone into a temporary folder), or where $HIYARI_SHARED says."""

from __future__ import annotations

import subprocess
from pathlib import Path

from hiyari.checkout import ENV_SHARED, shared_dir


def test_a_clone_elsewhere_finds_the_shared_folder_of_its_origin(tmp_path, monkeypatch) -> None:
    monkeypatch.delenv(ENV_SHARED, raising=False)
    origin = tmp_path / "work" / "main"
    origin.mkdir(parents=True)
    (tmp_path / "work" / "shared").mkdir()
    subprocess.run(["git", "init", "-q", str(origin)], check=True)
    clone = tmp_path / "elsewhere" / "clone"
    clone.parent.mkdir()
    subprocess.run(["git", "clone", "-q", str(origin), str(clone)], check=True, capture_output=True)
    assert shared_dir(origin) == tmp_path / "work" / "shared"
    assert shared_dir(clone) == (tmp_path / "work" / "shared").resolve()
    monkeypatch.setenv(ENV_SHARED, "/somewhere")
    assert shared_dir(clone) == Path("/somewhere")


def test_no_shared_folder_anywhere_names_the_sibling(tmp_path, monkeypatch) -> None:
    monkeypatch.delenv(ENV_SHARED, raising=False)
    assert shared_dir(tmp_path / "repo") == tmp_path / "shared"
