"""The first-run note comes with the first real compilation, once, and never for a command
that does not simulate or compiles nothing (bad input stops with its one error line)."""

from __future__ import annotations

import io

from numba import njit
from numba.core import event

from hiyari.bridge.cli import first_run
from hiyari.bridge.cli.first_run import NOTE, CompileNote, first_run_note


def _fresh_kernel():  # a new function object: numba has not compiled it in this process
    @njit(cache=False)
    def add_one(x: float) -> float:
        return x + 1.0

    return add_one


def test_the_note_is_printed_once_at_the_first_compilation() -> None:
    out = io.StringIO()
    listener = CompileNote(out)
    with event.install_listener("numba:compile", listener):
        assert out.getvalue() == "", "nothing before a compilation starts"
        assert _fresh_kernel()(1.0) == 2.0
        assert _fresh_kernel()(2.0) == 3.0
    assert out.getvalue() == NOTE + "\n"


def test_a_cached_or_compiled_kernel_prints_nothing() -> None:
    kernel = _fresh_kernel()
    kernel(1.0)  # compiled before the listener exists
    out = io.StringIO()
    with event.install_listener("numba:compile", CompileNote(out)):
        kernel(5.0)
    assert out.getvalue() == ""


def test_only_simulating_commands_on_a_cold_cache_listen(capsys, monkeypatch) -> None:
    assert first_run_note("doctor") is None
    monkeypatch.setattr(first_run, "kernels_cached", lambda: True)
    assert first_run_note("run") is None
    monkeypatch.setattr(first_run, "kernels_cached", lambda: False)
    _fresh_kernel()(1.0)
    assert NOTE not in capsys.readouterr().err
    listener = first_run_note("run")
    try:
        _fresh_kernel()(1.0)
        assert capsys.readouterr().err == NOTE + "\n"
    finally:
        event.unregister("numba:compile", listener)
