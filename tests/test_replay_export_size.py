"""The static replay thins LiDAR clouds in the page only, says so on it, and gets smaller."""

from __future__ import annotations

from pathlib import Path

import pytest
from test_recording_data import record_run

from hiyari.bridge.record.reader import Recording
from hiyari.bridge.replay.export import export_html, hud_label
from hiyari.bridge.replay.scene import FrameInfo
from hiyari.errors import HiyariError


def test_thinned_lidar_page_is_smaller_and_says_so(
    intersection_net: Path, intersection_demand: Path, tmp_path: Path
) -> None:
    run = record_run(intersection_net, intersection_demand, tmp_path / "run.mcap", 6.0)
    rec = Recording.open(run.path)
    full = export_html(rec, tmp_path / "all.html", progress=False, lidar_every=1)
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
