"""Unit tests run no simulation: starting SUMO here is an error (end-to-end tests live in
tests/e2e). Keeps the unit tests fast and the split honest."""

from __future__ import annotations

import pytest


@pytest.fixture(autouse=True)
def _no_sumo(monkeypatch: pytest.MonkeyPatch) -> None:
    import libsumo

    def refuse(*_args: object, **_kwargs: object) -> None:
        raise AssertionError("a unit test started SUMO: move it to tests/e2e")

    monkeypatch.setattr(libsumo, "start", refuse)
    monkeypatch.setattr(libsumo, "load", refuse)
