"""The one error type the CLI turns into a single line and a non-zero exit."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator


class HiyariError(Exception):
    """A user-facing problem (bad file, impossible parameter) described in one line.

    The message should name the file or parameter and say what is wrong with it.
    """

    def __init__(self, message: str) -> None:
        # one line whatever the source said (SUMO and lxml messages can span lines)
        super().__init__(" ".join(str(message).split()))


@contextlib.contextmanager
def about(path: str | os.PathLike[str], *also: str | os.PathLike[str]) -> Iterator[None]:
    """Errors raised inside concern the user's file ``path``: a HiyariError whose message
    names neither ``path`` nor one of ``also`` first gets ``path: `` in front, so the one line
    the CLI prints always starts with the file the user gave (not a generated one)."""
    try:
        yield
    except HiyariError as exc:
        message = str(exc)
        if any(message.startswith(str(p)) for p in (path, *also)):
            raise
        raise HiyariError(f"{path}: {message}") from None
