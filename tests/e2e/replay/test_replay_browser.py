"""End to end: ``hiyari replay`` serves a recorded SUMO run on 127.0.0.1 and headless Chromium
(Debian's /usr/bin/chromium, WebGL through SwiftShader) renders it; the test moves the
timeline, follows the ego, steps, toggles a layer, and checks the screenshots' pixels. The
static HTML export is opened from a file with every network request blocked.

Set HIYARI_REPLAY_SCREENSHOT=path.png to keep the screenshot of the busy frame (the README's
docs/replay.png comes from here).
"""

from __future__ import annotations

import os
import re
import shutil
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest
from recording_data import record_run

from hiyari.bridge.cli.main import main
from hiyari.bridge.record.style import CLASS_COLORS, EGO_COLOR
from hiyari.traffic import ActorClass

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-quic",
]
#: The page's size, px. SwiftShader renders every frame on the CPU, so each screenshot costs
#: time in proportion to the pixels: 768 x 480 is the smallest size at which viser's panel
#: still leaves the scene most of the width.
VIEW = {"width": 768, "height": 480}
#: Playwright's limit for every wait and screenshot, ms. Software WebGL on a loaded 2-core
#: machine can take tens of seconds per frame; the waits end as soon as their condition holds,
#: so a generous limit costs nothing when the machine is idle.
PAGE_TIMEOUT_MS = 180_000
#: How long a picture may take to show what the test waits for, s.
IMAGE_TIMEOUT_S = 120.0
# The 3D view without the GUI panel (right) and the axes gizmo (bottom left).
SCENE = (slice(0, VIEW["height"] - 80), slice(0, VIEW["width"] - 350))

playwright = pytest.importorskip("playwright.sync_api")
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian chromium is not installed"),
]


def _hue_mask(img: np.ndarray, rgb: tuple[int, int, int], tol_deg: float = 12.0) -> np.ndarray:
    """Pixels of ``img`` (RGB) with the hue of ``rgb`` and clearly saturated."""
    hsv = cv2.cvtColor(img, cv2.COLOR_RGB2HSV)
    target = cv2.cvtColor(np.uint8([[rgb]]), cv2.COLOR_RGB2HSV)[0, 0, 0]
    diff = np.abs(hsv[..., 0].astype(int) - int(target))
    diff = np.minimum(diff, 180 - diff)  # OpenCV hue is degrees / 2, circular
    return (diff <= tol_deg / 2) & (hsv[..., 1] > 90) & (hsv[..., 2] > 60)


def count(img: np.ndarray, rgb: tuple[int, int, int]) -> int:
    """Number of scene pixels in the colour of ``rgb``."""
    return int(_hue_mask(img[SCENE], rgb).sum())


def actor_pixels(img: np.ndarray) -> int:
    """Scene pixels in any actor-class colour or the ego's."""
    return sum(count(img, c) for c in (*CLASS_COLORS.values(), EGO_COLOR))


def screenshot(page) -> np.ndarray:
    png = page.screenshot()
    return cv2.cvtColor(
        cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB
    )


def rendered(page) -> None:
    """Wait for the page to draw two more frames: the state it shows now is on the canvas."""
    page.evaluate("() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")


def new_page(browser):
    page = browser.new_page(viewport=VIEW)
    page.set_default_timeout(PAGE_TIMEOUT_MS)
    return page


def wait_for_image(
    page, ok: Callable[[np.ndarray], bool], timeout: float = IMAGE_TIMEOUT_S
) -> np.ndarray:
    """Screenshots until ``ok`` holds (software WebGL needs a moment); returns the last one."""
    deadline = time.monotonic() + timeout
    rendered(page)
    while True:
        img = screenshot(page)
        if ok(img) or time.monotonic() > deadline:
            return img
        time.sleep(0.4)


def hide_notifications(page) -> None:
    """Hide viser's 'software WebGL' notice so it does not cover the scene."""
    page.add_style_tag(content="[class*=Notification] { display: none !important; }")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def recording(intersection_net, intersection_demand, tmp_path_factory):
    """A 30 s recorded run and the frame where the most actors are near the ego."""
    out = tmp_path_factory.mktemp("replay") / "run.mcap"
    run = record_run(intersection_net, intersection_demand, out, 30.0)

    def near(k: int) -> int:
        s, ego = run.states[k], run.ego[k]
        if ego is None:
            return -1
        d = np.hypot(*(s.xyz[:, :2] - s.xyz[s.index(ego), :2]).T)
        return int(np.sum(d < 30.0))

    busy = max(range(len(run.states) - 10), key=near)
    return run, busy


@pytest.fixture(scope="module")
def browser():
    with playwright.sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


def test_replay_server_renders_the_run(recording, browser, tmp_path):
    run, k = recording
    n = len(run.states)
    port = _free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "hiyari", "replay", str(run.path), "--port", str(port)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    watchdog = threading.Timer(PAGE_TIMEOUT_MS / 1000 * 2, proc.kill)
    watchdog.start()
    try:
        url = None
        for line in proc.stdout:
            m = re.search(r"replay of .* at (http://127\.0\.0\.1:\d+/)", line)
            if m:
                url = m.group(1)
                break
        assert url == f"http://127.0.0.1:{port}/"
        page = new_page(browser)
        page.goto(url)
        page.get_by_text(f"frame 1 / {n}").wait_for()  # the heads-up text: the page is live
        hide_notifications(page)
        # first frame (t = 0.1 s): the road is drawn, no actor has entered yet
        first = wait_for_image(page, lambda im: im[SCENE].std() > 10)
        assert first[SCENE].std() > 10
        assert actor_pixels(first) == 0

        # move the timeline to the busy frame by typing its time, then follow the ego
        t = run.states[k].time
        time_box = page.locator("input[type=text]").first
        time_box.fill(f"{t:.1f}")
        time_box.press("Enter")
        time_box.blur()  # a focused box would send its old value back when the server moves it
        page.get_by_text(f"frame {k + 1} / {n}").wait_for()
        page.get_by_label("Follow ego").dispatch_event("click")
        busy = wait_for_image(page, lambda im: count(im, EGO_COLOR) > 50)
        cv2.imwrite(str(tmp_path / "busy.png"), busy[..., ::-1])
        ego_px = count(busy, EGO_COLOR)
        assert ego_px > 50, "the ego (highlighted) is not on screen"
        others = count(busy, CLASS_COLORS[ActorClass.CAR]) + count(
            busy, CLASS_COLORS[ActorClass.PEDESTRIAN]
        )
        assert others > 30, "no other car or pedestrian drawn near the ego"
        if os.environ.get("HIYARI_REPLAY_SCREENSHOT"):
            shutil.copy(tmp_path / "busy.png", os.environ["HIYARI_REPLAY_SCREENSHOT"])
        assert page.get_by_text("AEB").count() >= 1  # heads-up display shows the ego status

        # step forward three frames: the scene changes
        for i in range(1, 4):
            # a DOM click: playwright's actionability checks wait for animation frames, which
            # software WebGL makes slow; one click at a time, as a person would
            page.get_by_role("button", name="Step forward").dispatch_event("click")
            page.get_by_text(f"frame {k + 1 + i} / {n}").wait_for()
        moved = wait_for_image(
            page, lambda im: np.abs(im.astype(int) - busy.astype(int))[SCENE].mean() > 0.5
        )
        assert np.abs(moved.astype(int) - busy.astype(int))[SCENE].mean() > 0.5

        # hide the vehicle layer: the ego box disappears
        page.get_by_label("vehicles", exact=True).dispatch_event("click")
        hidden = wait_for_image(page, lambda im: count(im, EGO_COLOR) < ego_px // 20)
        assert count(hidden, EGO_COLOR) < ego_px // 20
        page.close()
    finally:
        proc.terminate()
        code = proc.wait(timeout=60)
        watchdog.cancel()
    assert code == 0


def test_static_export_plays_without_a_server(recording, browser, tmp_path):
    run, k = recording
    t = run.states[k].time
    out = tmp_path / "replay.html"
    args = [
        "replay",
        str(run.path),
        "--export",
        str(out),
        "--start",
        f"{t - 1:.1f}",
        "--end",
        f"{t + 1:.1f}",
        "-q",
    ]
    assert main(args) == 0
    assert "__VISER_EMBED_DATA__" in out.read_text()
    page = new_page(browser)
    blocked = []

    def local_only(route):
        if route.request.url.startswith(("file:", "data:", "blob:")):
            route.continue_()
        else:
            blocked.append(route.request.url)
            route.abort()

    page.route("**/*", local_only)
    page.goto(out.as_uri())
    page.locator("input").first.wait_for()  # the player's controls: the embedded data is read
    hide_notifications(page)
    drawn = wait_for_image(page, lambda im: im[SCENE].std() > 10)
    assert drawn[SCENE].std() > 10
    # The player loops the 2 s clip while software WebGL takes a second or more per
    # screenshot, so a playing page shows whichever frame it is at. Pause it and seek: each
    # frame is then one image.
    page.locator("button").first.dispatch_event("click")  # the player's play / pause
    shots = [seek_static(page, s) for s in (0.5, 1.5)]
    for s, img in zip((0.5, 1.5), shots, strict=True):
        assert actor_pixels(img) > 25, f"no actors drawn at {s} s of the clip"
        # the view follows the ego: a car-sized pink box near the middle of the view, not a
        # speck on the whole road (issue 36)
        ego = _hue_mask(img[: VIEW["height"] - 80], EGO_COLOR, tol_deg=24.0)  # lit faces
        assert ego.sum() > 400, f"the ego is {ego.sum()} pixels at {s} s"
        ys, xs = np.nonzero(ego)
        assert abs(xs.mean() / VIEW["width"] - 0.5) < 0.1, xs.mean()
        assert abs(ys.mean() / (VIEW["height"] - 80) - 0.5) < 0.2, ys.mean()
    moved = np.abs(shots[1].astype(int) - shots[0].astype(int))[SCENE].max(-1) > 60
    assert moved.sum() > 20, "the scene did not change between two frames of the clip"
    assert not blocked, f"the static page asked the network for {blocked[:3]}"
    page.close()


def seek_static(page, t: float) -> np.ndarray:
    """Move a paused static player to ``t`` (s from the clip's start) and return the settled
    screenshot (the same image twice in a row)."""
    box = page.locator("input").first
    box.fill(f"{t:.1f}")
    box.press("Enter")
    box.blur()
    deadline = time.monotonic() + IMAGE_TIMEOUT_S
    rendered(page)
    last = screenshot(page)
    while True:
        time.sleep(0.4)
        img = screenshot(page)
        settled = box.input_value() == f"{t:.1f}" and np.array_equal(img, last)
        if settled or time.monotonic() > deadline:
            return img
        last = img
