"""Where the shared third-party data of a source checkout is (the specs, the OpenDRIVE roads,
the ALKS and Euro NCAP scenario sets): ``$HIYARI_SHARED``, else ``shared/`` beside the
checkout, else ``shared/`` beside the checkout it was cloned from (a clone into a temporary
folder finds the data of the checkout it came from)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

#: The environment variable naming the shared folder.
ENV_SHARED = "HIYARI_SHARED"

_ROOT = Path(__file__).resolve().parents[1]


def shared_dir(root: Path = _ROOT) -> Path:
    """The shared folder for the checkout at ``root`` (returned even when it does not exist,
    as ``root``'s sibling, so that a missing file is named where it was looked for)."""
    env = os.environ.get(ENV_SHARED)
    if env:
        return Path(env)
    beside = root.parent / "shared"
    if beside.is_dir():
        return beside
    try:
        origin = subprocess.run(
            ["git", "-C", str(root), "config", "--get", "remote.origin.url"],
            capture_output=True, text=True, timeout=10, check=False,
        ).stdout.strip()  # fmt: skip
    except OSError:
        origin = ""
    if origin and "://" not in origin and ":" not in origin.split("/", 1)[0]:
        cloned_from = (root / origin).resolve().parent / "shared"
        if cloned_from.is_dir():
            return cloned_from
    return beside
