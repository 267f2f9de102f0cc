"""``hiyari evaluate`` end to end on a small cell selection (real SUMO), and its HTML report in
headless Chromium (Debian's chromium through Playwright): an overall verdict in a failure
colour, the pass rule with its tolerance, counts true for the partial selection, the reasons
for excluded cells, parameters in users' units, replay pages of the failures, the traceable
run configuration, and a matrix whose failed cells are red (no shade between pass and fail)."""

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
    # replay pages beside the recordings, linked from the failures
    for rec in (report / "recordings").glob("*.mcap"):
        page = rec.with_suffix(".html")
        assert "__VISER_EMBED_DATA__" in page.read_text()
        assert f"recordings/{page.name}" in md


def test_ensure_coverage_writes_the_page_once(tmp_path: Path) -> None:
    """The demo's report includes the perception coverage: written when missing, kept when
    there (the demo and ``hiyari evaluate`` share it)."""
    from hiyari.bridge.studies.catalogue.structures import ensure_coverage

    folder = ensure_coverage(tmp_path / "structures")
    page = folder / "coverage.md"
    assert "principles exercised" in page.read_text()
    stamp = page.stat().st_mtime_ns
    ensure_coverage(folder)
    assert page.stat().st_mtime_ns == stamp


def test_report_opens_in_headless_chromium_and_shows_the_matrix(report: Path) -> None:
    with playwright.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        page = browser.new_page(viewport={"width": 1400, "height": 900})
        page.goto((report / "report.html").as_uri())
        assert page.locator("h1").inner_text().startswith("Safety argument")
        coverage = page.locator("img[alt=coverage]")
        assert coverage.evaluate("img => img.complete && img.naturalWidth") > 500
        assert page.locator("h3#coverage ~ table").count() >= 1
        # the overall verdict, in white on the failure red
        verdict = page.locator("#verdict")
        assert verdict.inner_text() == "FAIL"
        assert verdict.evaluate("e => getComputedStyle(e).backgroundColor") == "rgb(198, 40, 40)"
        text = page.locator("body").inner_text()
        assert "2 of 4 runs failed" in text and "2 of the 82 applicable cells run (partial" in text
        assert "C&C driver's + 1 m/s" in page.locator("#rule").inner_text()
        summary = page.locator("h2:text('Summary') + table").inner_text()
        assert "of which run in this report\t2" in summary
        assert "concrete runs\t4 in 2 cells" in summary
        assert "undefined (the motion is not defined from that position)" in summary
        key = page.locator("#status-key").inner_text()
        assert "a vehicle already in the ego's lane cannot cut in" in key
        # failures: parameters in km/h, a replay page that exists
        fails = page.locator("h2:text('Failures') + table")
        assert " km/h;" in fails.inner_text() and "m/s² (" in fails.inner_text()
        replay = fails.locator("a:text('replay')").first.get_attribute("href")
        assert replay.endswith(".html") and (report / replay).is_file()
        # traceability
        conf = page.locator("h2#configuration + table").inner_text()
        for needle in ("date (UTC)", "git commit", "version hiyari", "version numpy",
                       "version eclipse-sumo", "seeds\t0:", "range: ego speed\t60.0 km/h to "
                       "120.0 km/h", "evaluate --cells M02-front-2L,M03-left_rear-2L"):  # fmt: skip
            assert needle in conf, needle
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
    # M02-front fails, M03-left_rear passes: red and green only, no olive or amber between
    green = (g > 100) & (r < 80) & (b < 80)  # passed cells (#2e7d32)
    assert green.sum() > 500
    between = (r > 120) & (g > 100) & (b < 60)  # the old red-to-green ramp's yellows
    assert between.sum() < 20
