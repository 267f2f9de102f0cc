"""The model definitions the code and help texts cite are in the repository: every
"docs/models.md §N" in the sources names a section the page has, and nothing cites a file
outside it."""

from __future__ import annotations

import re
from pathlib import Path

from paths import REPO_ROOT

ROOT = REPO_ROOT
SOURCES = [p for p in ROOT.rglob("*.py") if ".venv" not in p.parts and "build" not in p.parts]


def test_every_models_citation_names_a_section_of_docs_models() -> None:
    page = (ROOT / "docs" / "models.md").read_text(encoding="utf-8")
    sections = set(re.findall(r"^## (\d+)\. ", page, re.M))
    assert sections == {"1", "2", "3", "4"}
    cited = {
        (p.relative_to(ROOT).as_posix(), n)
        for p in SOURCES
        for n in re.findall(r"docs/models\.md (?:§|section )(\d+)", p.read_text(encoding="utf-8"))
    }
    assert len(cited) >= 10  # the driver model, SCT, sensors and fusion all cite it
    assert {n for _, n in cited} <= sections, cited


def test_no_citation_of_a_file_outside_the_repository() -> None:
    offenders = [
        p.relative_to(ROOT).as_posix()
        for p in SOURCES
        if p.name != Path(__file__).name
        and re.search(r"MODELS\.md|shared/spec", p.read_text(encoding="utf-8"))
    ]
    assert offenders == []
