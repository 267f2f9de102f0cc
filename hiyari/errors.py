"""The one error type the CLI turns into a single line and a non-zero exit."""

from __future__ import annotations

import contextlib
import errno
import os
from collections.abc import Iterator


class HiyariError(Exception):
    """A user-facing problem (bad file, impossible parameter) described in one line.

    The message should name the file or parameter and say what is wrong with it.
    """

    def __init__(self, message: str) -> None:
        # one line whatever the source said (SUMO and lxml messages can span lines)
        super().__init__(" ".join(str(message).split()))


class WriteFailed(HiyariError):
    """An output could not be written: the disk is full (ENOSPC, or EFBIG / EDQUOT at a size
    or quota limit), the device failed (EIO) or is read-only (EROFS)."""


#: errno values that make an OSError of a write a :class:`WriteFailed`.
WRITE_ERRNOS = frozenset({errno.ENOSPC, errno.EIO, errno.EFBIG, errno.EDQUOT, errno.EROFS})


@contextlib.contextmanager
def writing(path: str | os.PathLike[str], outcome: str = "") -> Iterator[None]:
    """Writes to ``path`` inside: an OSError of a full disk or a failed device becomes a
    WriteFailed naming ``path`` (``outcome``: what is left, appended to the line)."""
    try:
        yield
    except OSError as exc:
        if exc.errno not in WRITE_ERRNOS:
            raise
        tail = f"; {outcome}" if outcome else ""
        raise WriteFailed(f"{path}: cannot write: {os.strerror(exc.errno)}{tail}") from None


@contextlib.contextmanager
def about(path: str | os.PathLike[str], *also: str | os.PathLike[str]) -> Iterator[None]:
    """Errors raised inside concern the user's file ``path``: a HiyariError whose message
    names neither ``path`` nor one of ``also`` first gets ``path: `` in front, so the one line
    the CLI prints always starts with the file the user gave (not a generated one). A
    WriteFailed is about an output, and names it: it goes on as it is."""
    try:
        yield
    except HiyariError as exc:
        message = str(exc)
        if isinstance(exc, WriteFailed) or any(message.startswith(str(p)) for p in (path, *also)):
            raise
        raise HiyariError(f"{path}: {message}") from None


@contextlib.contextmanager
def unmasked_interrupts() -> Iterator[None]:
    """A Ctrl-C (or SIGTERM delivered as one) that a library turned into another exception is
    raised again as itself: numba raises a SystemError when the interrupt lands while it loads
    a cached kernel, and an interrupted run must keep what it wrote, not be taken for a failed
    one."""
    try:
        yield
    except Exception as exc:
        cause: BaseException | None = exc
        while cause is not None and not isinstance(cause, KeyboardInterrupt):
            cause = cause.__cause__ or cause.__context__
        if cause is None:
            raise
        raise type(cause)(*cause.args) from None
