"""``hiyari ncap`` end to end on a reduced grid (CCRs and CPNA-25 at 50 km/h: 5 + 2 points, day
and night) on real SUMO: an interrupted study keeps its rows and resumes; a deliberately
weaker AEB scores strictly lower on the same grid; no AEB scores 0; bad input is one line with
exit 1 and writes nothing. The report opens in headless Chromium with its colour grids."""

from __future__ import annotations

import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from paths import REPO_ROOT

from hiyari.bridge.cli import status
from hiyari.bridge.cli.main import main

sys.path.insert(
    0, str(REPO_ROOT / "tests" / "support")
)  # --stack ncap_stacks:... (forked workers too)

GRID = ["ncap", "--tests", "CCRs,CPNA-25", "--speeds", "50", "-q"]
pytestmark = pytest.mark.slow


def _score(out: Path) -> dict[str, float]:
    doc = json.loads((out / "score.json").read_text())
    return {p: doc[p]["points"] for p in doc}


def _rows(out: Path) -> list[dict]:
    with (out / "results.csv").open(newline="") as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def default(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The default stack's study, interrupted by Ctrl-C after its first point, then resumed."""
    out = tmp_path_factory.mktemp("ncap") / "default"
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:  # Ctrl-C enabled as in a terminal's foreground job (see test_cli_interrupt._start)
        proc = subprocess.Popen(
            [sys.executable, "-m", "hiyari", *GRID, "-j", "1", "-o", str(out)],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
            start_new_session=True,
        )  # fmt: skip
    finally:
        signal.signal(signal.SIGINT, previous)
    table, deadline = out / "results.csv", time.time() + 120
    while proc.poll() is None and time.time() < deadline:
        if table.is_file() and len(table.read_text().splitlines()) >= 2:
            break
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == status.INTERRUPTED, err
    assert err.count("\n") == 1 and "test points are kept" in err and "resume" in err
    kept = len(_rows(out))
    assert 1 <= kept < 7
    assert not (out / "report.html").exists() and not (out / "score.json").exists()
    assert main([*GRID, "-j", "2", "-o", str(out)]) == status.OK  # resumes: every point green
    assert len(_rows(out)) == 7
    conf = (out / "report.html").read_text()
    assert f"{7 - kept} / {kept}" in conf  # points run now / kept from before
    return out


def test_resumed_study_scores_full_marks(default: Path) -> None:
    assert _score(default) == {"c2c": 1.0, "vru": 1.0}  # CCRs: 1 point (SA 3.3.2)
    rows = _rows(default)
    assert [r["point_id"] for r in rows][:2] == ["CCRs-day-040", "CCRs-day-041"]
    assert {r["lighting"] for r in rows if r["test"] == "CPNA-25"} == {"day", "night"}
    assert all(r["contact"] == "False" and r["warning_ttc_s"] for r in rows)


@pytest.mark.parametrize("stack", ["half_ttc", "late_brake"])
def test_weaker_aeb_scores_strictly_lower(default: Path, tmp_path: Path, stack: str) -> None:
    out = tmp_path / stack
    code = main([*GRID, "-j", "2", "--no-replays", "--stack", f"ncap_stacks:{stack}",
                 "-o", str(out)])  # fmt: skip
    assert code == status.VERDICT_FAIL  # points lost
    weak, full = _score(out), _score(default)
    assert all(weak[p] < full[p] for p in full), (weak, full)
    lost = [r for r in _rows(out) if r["contact"] == "True"]
    assert lost and all((out / "recordings" / f"{r['point_id']}.mcap").is_file() for r in lost)


def test_no_aeb_scores_zero(tmp_path: Path) -> None:
    out = tmp_path / "none"
    code = main([*GRID, "-j", "2", "--no-replays", "--stack", "ncap_stacks:no_aeb",
                 "-o", str(out)])  # fmt: skip
    assert code == status.VERDICT_FAIL
    assert _score(out) == {"c2c": 0.0, "vru": 0.0}
    # hit at the test speed: the impact is the test speed (to the 0.01 km/h of SUMO's step)
    for r in _rows(out):
        assert r["contact"] == "True"
        assert float(r["impact_speed_kmh"]) == pytest.approx(50.0, abs=0.01)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--protocol", "pedestrians"], "invalid choice: 'pedestrians'"),
        (["--tests", "CCRs,XYZ"], "--tests: XYZ not in protocol all"),
        (["--files", "/nonexistent/ncap"], "/nonexistent/ncap/OpenSCENARIO/NCAP/AEB_C2C_2023"),
        (["--stack", "no_such_module:f"], "--stack: cannot load 'no_such_module:f'"),
        (["--environment", "snow"], "--environment: unknown disturbance preset 'snow'"),
        (["--speeds", "33"], "--speeds 33: no test point has these speeds"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str
) -> None:
    out = tmp_path / "out"
    code = main(["ncap", "--tests", "CCRs", "--speeds", "50", *args, "-o", str(out)])
    err = capsys.readouterr().err
    assert code == status.ERROR and message in err
    assert err.strip().count("\n") == 0 or err.startswith("usage:")
    assert not out.exists()


def test_a_foreign_results_table_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.csv").write_text("index,seed\n0,1\n")
    assert main(["ncap", "--tests", "CCRs", "--speeds", "50", "-o", str(out)]) == status.ERROR
    assert "not a 'hiyari ncap' results table" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["results.csv"]


CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"


@pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian chromium is not installed")
def test_report_in_headless_chromium_shows_the_grids(tmp_path: Path) -> None:
    """A weak AEB loses points at 50 km/h: brown cells in the grids, linked recordings and
    replays of the points that lost points."""
    playwright = pytest.importorskip("playwright.sync_api")
    out = tmp_path / "weak"
    main(["ncap", "--tests", "CPNA-25", "--speeds", "20,50", "-q", "-j", "2",
          "--stack", "ncap_stacks:half_ttc", "-o", str(out)])  # fmt: skip
    args = ["--no-sandbox", "--disable-gpu", "--disable-background-networking"]
    with playwright.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=args)
        page = browser.new_page(viewport={"width": 1300, "height": 900})
        page.goto((out / "report.html").as_uri())
        assert page.locator("h1").inner_text() == "Euro NCAP 2023 AEB datasheet"
        assert page.locator("h2#lost").inner_text() == "Points that lost points (2)"
        links = page.locator("h2#lost + table a")
        assert sorted(links.all_inner_texts()) == [
            "CPNA-25-day-008.html", "CPNA-25-day-008.mcap",
            "CPNA-25-night-008.html", "CPNA-25-night-008.mcap",
        ]  # fmt: skip
        grid = page.locator("img.grid")
        assert grid.evaluate("img => img.complete && img.naturalWidth") > 400
        png = grid.screenshot()
        browser.close()
    import cv2

    img = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)[..., ::-1].astype(int)
    green = (abs(img[..., 0] - 0) < 8) & (abs(img[..., 1] - 153) < 8) & (abs(img[..., 2] - 51) < 8)
    brown = (abs(img[..., 0] - 150) < 8) & (abs(img[..., 1] - 75) < 8) & (abs(img[..., 2]) < 8)
    assert green.sum() > 2000 and brown.sum() > 2000  # 20 km/h avoided, 50 km/h brown


def test_a_folder_resumes_only_the_same_study(default: Path, capsys: pytest.CaptureFixture) -> None:
    before = (default / "results.csv").read_text()
    code = main([*GRID, "--stack", "ncap_stacks:no_aeb", "-o", str(default)])
    assert code == status.ERROR
    err = capsys.readouterr().err
    assert "its results were made with stack 'hiyari NCAP stack', not 'ncap_stacks:no_aeb'" in err
    assert (default / "results.csv").read_text() == before
