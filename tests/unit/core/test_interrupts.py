"""A Ctrl-C that a library masks as another exception (numba: a SystemError when the interrupt
lands while it unpickles a cached kernel) is still an interrupt: the run keeps its recording's
.part file, and the CLI says "interrupted", not a traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

from hiyari.bridge.loop.execute import RunOptions, run_folder
from hiyari.errors import unmasked_interrupts


class Terminated(KeyboardInterrupt):
    """As the CLI's SIGTERM."""


def _masked(interrupt: KeyboardInterrupt) -> None:
    try:
        raise interrupt
    except KeyboardInterrupt:
        # implicit chaining (__context__), as a C extension leaves it
        raise SystemError("<built-in function loads> returned a result with an exception set")  # noqa: B904


def test_a_masked_interrupt_is_an_interrupt_again() -> None:
    with pytest.raises(KeyboardInterrupt), unmasked_interrupts():
        _masked(KeyboardInterrupt())
    with pytest.raises(Terminated), unmasked_interrupts():
        _masked(Terminated())


def test_other_errors_pass_unchanged() -> None:
    with pytest.raises(SystemError), unmasked_interrupts():
        raise SystemError("a real one")
    with pytest.raises(ValueError), unmasked_interrupts():
        try:
            raise OSError("no interrupt in the chain")
        except OSError:
            raise ValueError("chained") from None


def test_a_masked_interrupt_keeps_the_recording_so_far(tmp_path: Path) -> None:
    options = RunOptions(recording=tmp_path / "out" / "run.mcap")
    part = tmp_path / "out" / "run.mcap.part"
    with pytest.raises(KeyboardInterrupt), run_folder(options), unmasked_interrupts():
        part.parent.mkdir()
        part.write_bytes(b"the steps recorded so far")
        _masked(KeyboardInterrupt())
    assert part.read_bytes() == b"the steps recorded so far"
