"""Where the repository and the shared third-party data are, for tests at any depth."""

from __future__ import annotations

from pathlib import Path

from hiyari.checkout import shared_dir

#: the repository's root (pyproject.toml, README.md)
REPO_ROOT = Path(__file__).resolve().parents[2]
#: ../shared beside the repository: the specs and the third-party data (data/README.md)
SHARED = shared_dir(REPO_ROOT)
