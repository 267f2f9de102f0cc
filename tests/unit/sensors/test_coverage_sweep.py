"""Representative-factor sweep on the real ray-cast sensors and fusion."""

from __future__ import annotations

import pytest

from hiyari.bridge.studies.perception.sweep import (
    SweepConfig,
    conditions,
    levels,
    sweep_disturbance,
)
from hiyari.bridge.studies.report.perception_sweep import write_sweep
from hiyari.errors import HiyariError
from hiyari.sensors.coverage.disturbances import load_disturbances
from hiyari.sensors.detection_range import RangeStudy


def test_dense_fog_shortens_lidar_range_but_not_radar_or_fused(tmp_path):
    reg = load_disturbances()
    cfg = SweepConfig(levels=2, targets=("car",), distances_m=(20.0, 60.0), frames=3)
    clear, fog = sweep_disturbance(reg.get("fog"), cfg)
    assert (clear.level, fog.level) == (1000.0, 30.0)
    # 30 m visibility: 905 nm two-way transmission to 60 m is exp(-2 * 3.9 / 30 * 60) ~ 2e-7
    assert clear.range_m["lidar"] == 60.0 and fog.range_m["lidar"] < 60.0
    assert fog.missed["lidar"] > 0.0
    assert fog.range_m["radar"] == clear.range_m["radar"] == 60.0  # 77 GHz barely notices fog
    assert fog.range_m["fused"] == 60.0
    paths = write_sweep([clear, fog], tmp_path)
    assert "| fog | 30 (m visibility) | car |" in paths["md"].read_text()
    assert paths["png"].read_bytes()[:4] == b"\x89PNG"


def test_levels_and_conditions():
    reg = load_disturbances()
    assert list(levels(reg.get("occluder"), 5)) == [0.0, 1.0]  # on / off: two levels
    assert list(levels(reg.get("snow"), 3)) == pytest.approx([2000.0, 447.2136, 100.0])
    preset, study = conditions(reg.get("axis_misalignment"), 4.0, RangeStudy())
    assert study.radar_mount.yaw_deg == 4.0 and study.lidar_mount.yaw_deg == 4.0
    preset, _ = conditions(reg.get("window_dirt_lidar"), 0.3, RangeStudy())
    assert preset.environment.for_sensor("lidar").soiling.uniform_transmission == 0.3
    assert preset.environment.for_sensor("radar").soiling.uniform_transmission == 1.0
    with pytest.raises(HiyariError, match="cannot be swept"):
        conditions(reg.get("target_type"), 1.0, RangeStudy())
