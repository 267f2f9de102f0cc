"""The OpenSCENARIO element table (docs/openscenario_elements.md) against the 1.3 schema and the
code: every element of the schema has a status, none is unknown to the code, the page is the
one the code makes, refusals carry their reasons, and the tests it names exist."""

from __future__ import annotations

from pathlib import Path

from lxml import etree
from paths import REPO_ROOT

from hiyari.bridge.openscenario import coverage
from hiyari.bridge.openscenario.xosc.context import Ctx, Scope

ROOT = REPO_ROOT


def test_every_schema_element_has_a_status() -> None:
    names = coverage.schema_elements()
    assert len(names) == 295 and "SynchronizeAction" in names
    unknown = [n for n in names if coverage.status(n)[0] == "unknown"]
    assert not unknown, f"in the schema, neither read nor refused by the code: {unknown}"
    listed = set(coverage.REFUSED) | set(coverage.NOT_YET) | set(coverage.READ) | coverage.IMPLICIT
    assert listed <= set(names), f"not elements of the schema: {sorted(listed - set(names))}"


def test_the_page_is_the_generated_table() -> None:
    page = (ROOT / "docs" / "openscenario_elements.md").read_text()
    assert page == coverage.table(), "regenerate: python -m hiyari.bridge.openscenario.coverage"


def test_refusals_give_their_reasons() -> None:
    ctx = Ctx(Path("f.xosc"), Scope())
    for tag, reason in (*coverage.REFUSED.items(), *coverage.NOT_YET.items()):
        msg = str(ctx.unsupported(etree.Element(tag)))
        assert (
            msg.startswith(f"f.xosc:None: <{tag}> is not supported by hiyari (") and reason in msg
        )


def test_named_tests_exist() -> None:
    for name in coverage.schema_elements():
        test = coverage.test_of(name)
        assert not test or any((ROOT / "tests").rglob(test)), test
