"""JAMA factor x principle matrices: counts against the digests, coverage, CLI."""

from __future__ import annotations

import subprocess
import sys
from collections import Counter

import pytest

from hiyari.bridge.studies.perception.coverage_run import parse_sensors, write_coverage
from hiyari.errors import HiyariError
from hiyari.sensors.coverage.coverage import merged_list, principle_coverage
from hiyari.sensors.coverage.disturbances import load_disturbances
from hiyari.sensors.coverage.matrices import load_matrix

# jama-B 3.6.2 / jama-C 9: the printed totals row of Table 4-23, columns c1..c30
RADAR_TOTALS = [2, 6, 13, 14, 6, 12, 12, 39, 8, 17, 13, 36, 8, 14, 19, 9, 1, 1]
RADAR_TOTALS += [8, 14, 19, 9, 1, 1, 5, 66, 118, 118, 118, 118]


def test_radar_table_shape_and_printed_totals():
    m = load_matrix("radar")
    assert len(m.factors) == 133  # jama-B 3.6.4: 133 factor rows
    assert len(m.principles) == 30  # 30 numbers in the totals row
    assert [p.printed_total for p in m.principles] == RADAR_TOTALS
    # rows with a nonzero count: 119 (jama-B 6.4: the sheet prints 118, the rows give 119)
    assert sum((f.applicable_items or 0) > 0 for f in m.factors) == 119


def test_radar_per_row_counts_match_the_digest():
    m = load_matrix("radar")
    counts = Counter(f.applicable_items for f in m.factors)
    # jama-C 9: per-row counts take the values 0, 1, 2, 3, 4, 5, 6 and 8
    assert set(counts) == {0, 1, 2, 3, 4, 5, 6, 8}
    by_row = {f.row: f for f in m.factors}
    # spot deposits 3, uniform layers 1, guard rail 5, road sign 4, tyre pressure 8 (jama-B)
    assert [by_row[r].applicable_items for r in (9, 8, 58, 61, 1, 3)] == [3, 1, 5, 4, 8, 6]
    assert by_row[8].effect == "missed" and by_row[9].effect == "false+missed"
    for f in m.factors:
        if f.principles_complete:
            assert len(f.principles) == f.applicable_items, f.row


def test_inferred_radar_columns_reproduce_the_confirmed_totals():
    m = load_matrix("radar")
    confirmed = [p for p in m.principles if p.total_confirmed]
    assert len(confirmed) == 16  # jama-C 3.1 ticks (c20-c24 mirror c14-c18)
    for p in confirmed:
        assert m.column_count(p.id) == p.printed_total, p.id


def test_lidar_and_camera_tables_load_with_their_columns():
    lidar, camera = load_matrix("lidar"), load_matrix("camera")
    # jama-C 4.1: scan timing 2, intensity 3, direction 2, speed 1, N 1, U 3, processing 2,
    # detection + clustering + tracking + classification 4 = 18 columns
    assert len(lidar.principles) == 18
    assert {f.factor_class for f in lidar.factors} >= {"a", "c", "e", "k-4"}
    assert not any(f.factor_class.startswith("h") for f in lidar.factors)  # no traffic info
    assert {f.row for f in camera.factors if f.effect == "none"}  # out-of-scope rows kept
    assert {f.factor_class for f in camera.factors} >= {"h-1", "h-2", "k-1", "k-4"}


def test_default_set_covers_weather_and_soiling_principles_and_names_gaps():
    matrices = {s: load_matrix(s) for s in ("camera", "radar", "lidar")}
    reg = load_disturbances()
    radar = {c.principle: c for c in principle_coverage(matrices["radar"], reg)}
    assert "rain" in radar["c11"].disturbances and "snow" in radar["c11"].disturbances
    assert radar["c2"].disturbances == ("guardrail_multipath",)
    assert not radar["c17"].covered and "interference" in radar["c17"].reasons[0]
    lidar = {c.principle: c for c in principle_coverage(matrices["lidar"], reg)}
    assert "spray" in lidar["l4"].disturbances
    merged = {r.disturbance: r for r in merged_list(matrices, reg)}
    assert set(merged["rain"].principles) == {"camera", "radar", "lidar"}
    assert "radar" not in merged["spray"].principles  # spray not in the radar model


def test_unknown_sensor_is_one_line_error():
    with pytest.raises(HiyariError, match="unknown sensor"):
        parse_sensors("camera,sonar")


def test_coverage_command_writes_markdown_and_png(tmp_path):
    text, paths = write_coverage(("camera", "radar", "lidar"), tmp_path)
    assert paths["png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert paths["md"].read_text() == text
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "hiyari.bridge.cli.main",
            "perception",
            "coverage",
            "--sensors",
            "radar",
            "-o",
            str(tmp_path / "cli"),
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "radar: 17 of 23 principles exercised" in out.stdout
