"""Output paths of the commands, checked before any work: a file where a folder is needed
(or the reverse), a parent that is a file, a folder that cannot be written. Each problem is
one HiyariError naming the option, the path and the problem; nothing is created here."""

from __future__ import annotations

import os
from pathlib import Path

from hiyari.errors import HiyariError


def output_folder(path: str | os.PathLike[str], option: str = "-o") -> Path:
    """``path`` as a folder the command may create or write into."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise HiyariError(f"{option} {out}: is a file, not a folder")
    _writable(out if out.is_dir() else out.parent, out, option)
    return out


def output_file(path: str | os.PathLike[str], option: str, make_parents: bool = True) -> Path:
    """``path`` as a file the command may create or replace; ``make_parents``: its folder may
    be created (else it must exist)."""
    out = Path(path)
    if out.is_dir():
        raise HiyariError(f"{option} {out}: is a folder, give a file name")
    if not make_parents and not out.parent.is_dir():
        raise HiyariError(f"{option} {out}: the folder {out.parent} does not exist")
    _writable(out.parent, out, option)
    return out


def _writable(folder: Path, out: Path, option: str) -> None:
    """Whether ``folder`` (created when missing) can hold ``out``: its nearest existing
    ancestor must be a folder this process may write in."""
    folder = Path(os.path.abspath(folder))
    existing = next(p for p in (folder, *folder.parents) if p.exists())
    if not existing.is_dir():
        raise HiyariError(f"{option} {out}: {existing} is a file, not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise HiyariError(f"{option} {out}: cannot write in {existing} (permission denied)")
