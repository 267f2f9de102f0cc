"""The static replay thins LiDAR clouds in the page only, says so on it, and gets smaller; it
prints nothing of the viser server it uses, labels the heads-up TTC as the stack's, and its
view follows the ego (the transform checked by hand; the pixels in tests/e2e/replay/test_replay_browser)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from recording_data import record_run

from hiyari.bridge.record.reader import Recording
from hiyari.bridge.replay.export import export_html, hud_label
from hiyari.bridge.replay.scene import FrameInfo, ego_frame_transform
from hiyari.bridge.replay.server import hud_markdown
from hiyari.errors import HiyariError


def test_thinned_lidar_page_is_smaller_and_says_so(
    intersection_net: Path, intersection_demand: Path, tmp_path: Path, capfd: pytest.CaptureFixture
) -> None:
    run = record_run(intersection_net, intersection_demand, tmp_path / "run.mcap", 6.0)
    rec = Recording.open(run.path)
    capfd.readouterr()
    full = export_html(rec, tmp_path / "all.html", progress=False, lidar_every=1)
    out, err = capfd.readouterr()
    assert out == "" and "viser" not in err  # no server banner, no "Server stopped"
    thin = export_html(rec, tmp_path / "thin.html", progress=False, lidar_every=8)
    # (most of this small page is the viser client itself; the demo page shrinks ~10x)
    assert thin.stat().st_size < 0.92 * full.stat().st_size
    # the recording itself is untouched: every point is still read back
    last = Recording.open(run.path).point_cloud_at("top", len(run.lidar) - 1)
    assert len(last) == len(run.lidar[-1]) > 100
    info = FrameInfo(0, 1.0, 2, 1, None, None, None, {})
    assert "1 in 8 points" in hud_label(info, 8)
    assert "LiDAR" not in hud_label(info, 1)
    with pytest.raises(HiyariError, match="lidar_every"):
        export_html(rec, tmp_path / "bad.html", progress=False, lidar_every=0)


def test_heads_up_ttc_is_the_stacks_and_a_dash_without_target() -> None:
    status = {"speed_mps": 10.0, "ttc_s": None, "aeb_state": "off", "accel_cmd_mps2": 0.0}
    info = FrameInfo(0, 1.0, 2, 0, "ego", None, status, {})
    assert "stack TTC —" in hud_label(info) and "stack TTC —" in hud_markdown(info, 10)
    info.ego_status = {**status, "ttc_s": 1.234}
    assert "stack TTC 1.2 s" in hud_label(info) and "stack TTC 1.23 s" in hud_markdown(info, 10)
    assert " TTC" not in hud_label(info).replace("stack TTC", "")


def test_ego_frame_puts_the_ego_at_the_origin_heading_x() -> None:
    """Ego box centre (10, 5, 0.75) heading north (90°): the transform takes it to the origin,
    a point 1 m ahead of it, (10, 6, 0.75), to (1, 0, 0) and one 2 m to its left, (8, 5, 0.75),
    to (0, 2, 0)."""
    position, wxyz = ego_frame_transform((np.array([10.0, 5.0, 0.75]), math.pi / 2))
    w, z = wxyz[0], wxyz[3]
    yaw = 2 * math.atan2(z, w)
    rot = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0],
                    [0, 0, 1]])  # fmt: skip
    for world, view in (((10, 5, 0.75), (0, 0, 0)), ((10, 6, 0.75), (1, 0, 0)),
                        ((8, 5, 0.75), (0, 2, 0))):  # fmt: skip
        assert rot @ np.array(world) + position == pytest.approx(view, abs=1e-12)
