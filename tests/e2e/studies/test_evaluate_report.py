"""``hiyari evaluate`` end to end on a small cell selection (real SUMO), and its HTML report in
headless Chromium (Debian's chromium through Playwright): the matrix image loads and shows
pass (green) and fail (red) cells."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from hiyari.bridge.cli.main import main

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--no-first-run"]

playwright = pytest.importorskip("playwright.sync_api")
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian chromium is not installed"),
]


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("evaluate")
    # no perception: the lead-braking runs fail, the cut-in from behind passes or is unpreventable
    code = main(["evaluate", "--cells", "M02-front-2L,M03-left_rear-2L", "--runs-per-cell", "2",
                 "--perception", "none", "-j", "1", "-q", "-o", str(out)])  # fmt: skip
    assert code == 3  # the runs completed and a verdict failed
    return out


def test_report_files_and_recordings(report: Path) -> None:
    assert (report / "report.md").read_text().startswith("# Safety argument")
    assert (report / "matrix.png").stat().st_size > 10_000
    assert (report / "datasheets" / "M02.png").is_file()
    md = (report / "report.md").read_text()
    assert "## Failures (2)" in md  # both lead-braking runs are Preventable and hit
    for rec in (report / "recordings").glob("*.mcap"):
        assert rec.name.startswith("M02-front-2L-")
    assert len(list((report / "recordings").glob("*.mcap"))) == 2
    # the perception structures: the coverage is always part of the argument; pages not run
    # are declared as not evaluated, never silently absent
    assert "### Perception: factor x principle coverage" in md
    assert "](structures/coverage.png)" in md and "principles exercised" in md
    assert md.count("Not evaluated in this report") == 3


def test_report_opens_in_headless_chromium_and_shows_the_matrix(report: Path) -> None:
    with playwright.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        page = browser.new_page(viewport={"width": 1400, "height": 900})
        page.goto((report / "report.html").as_uri())
        assert page.locator("h1").inner_text().startswith("Safety argument")
        coverage = page.locator("img[alt=coverage]")
        assert coverage.evaluate("img => img.complete && img.naturalWidth") > 500
        assert page.locator("h3#coverage ~ table").count() >= 1
        matrix = page.locator("img#matrix")
        assert matrix.evaluate("img => img.complete && img.naturalWidth") > 1000
        png = matrix.screenshot()
        browser.close()
    import cv2

    img = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)[..., ::-1]
    r, g, b = (img[..., i].astype(int) for i in range(3))
    red = (r > 150) & (g < 80) & (b < 80)  # failed cells (#c62828)
    grey = (abs(r - 224) < 4) & (abs(g - 224) < 4) & (abs(b - 224) < 4)  # not applicable
    assert red.sum() > 500
    assert grey.sum() > 5000
