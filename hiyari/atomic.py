"""Write outputs under a temporary name and rename them into place only when complete."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from hiyari.errors import writing


@contextlib.contextmanager
def atomic_path(target: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``target``; rename it to ``target`` on success.

    On any exception the temporary file (or folder) is removed and ``target`` is left as it
    was, so a crash never leaves a half-written output under the final name. A full disk or
    a failed device while writing is a WriteFailed naming ``target``.
    """
    target = Path(target)
    outcome = f"{target.name} is left as it was" if target.exists() else "nothing is written"
    with writing(target, outcome):
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
        os.close(fd)
        with _removed_on_error(Path(name)) as tmp:
            yield tmp
            if tmp.is_file():
                tmp.chmod(0o644)  # mkstemp creates 0600; outputs are ordinary files
            os.replace(tmp, target)


@contextlib.contextmanager
def _removed_on_error(tmp: Path) -> Iterator[Path]:
    try:
        yield tmp
    except BaseException:
        if tmp.is_dir():
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            tmp.unlink(missing_ok=True)
        raise


def write_text_atomic(target: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` to ``target`` atomically and return the final path."""
    with atomic_path(target) as tmp:
        tmp.write_text(text)
    return Path(target)


def append_bytes(target: str | os.PathLike[str], data: bytes, outcome: str = "") -> None:
    """Append ``data`` to ``target`` and hand it to the OS (a table growing row by row). A
    full disk or a failed device is a WriteFailed naming ``target`` (``outcome``: what is
    kept, for the message); ``target`` then ends in a cut line, which readers skip."""
    with writing(target, outcome), open(target, "ab") as f:
        f.write(data)
