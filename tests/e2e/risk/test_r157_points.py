"""UN R157 test points: Annex G placement, verdicts, files read back, CLI."""

from __future__ import annotations

import argparse
import json
from collections import Counter

import numpy as np
import pytest

from hiyari.bridge.cli.commands.evaluation import boundary as cmd_boundary
from hiyari.bridge.cli.commands.evaluation import r157 as cmd_r157
from hiyari.bridge.cli.main import main
from hiyari.errors import HiyariError
from hiyari.risk.cc.boundary import Grid, cut_in_boundary
from hiyari.risk.cc.evaluator import evaluate_cut_in, evaluate_cut_out
from hiyari.risk.cc.model import CCParams
from hiyari.risk.cc.r157_points import (
    R157Config,
    generate_points,
    load_points,
    point_tracks,
    write_points_csv,
    write_points_json,
)

KMH = 1 / 3.6
CONFIG = R157Config(ve0_kmh=Grid(30, 90, 30), dv_kmh=Grid(0, 40, 20), gx_max_g=Grid(0.5, 1, 0.5))


@pytest.fixture(scope="module")
def point_set():
    return generate_points(CONFIG)


def test_annex_g_placement(point_set):
    pts = point_set.points
    kinds = Counter((p.scenario, p.point) for p in pts)
    for label in (
        "boundary",
        "boundary+1m",
        "boundary+2m",
        "boundary+10m",
        "boundary+30m",
        "boundary-5m",
    ):
        assert kinds["cut-in", label] > 0, label
    assert kinds["cut-out", "boundary+30m"] > 0
    assert {p.point for p in pts if p.scenario == "decel"} == {"thw"}
    assert sum(k == "decel" for k, _ in kinds.elements()) == 3 * 2
    for p in pts:
        if p.scenario == "decel":
            assert p.boundary_m is None and p.vy_mps is None and p.gx_max_g in (0.5, 1.0)
            assert p.dx0_m == pytest.approx(2.0 * p.ve0_mps)
            continue
        gap = p.dx0_m if p.scenario == "cut-in" else p.dx0_f_m
        assert gap == pytest.approx(p.boundary_m + p.offset_m)
        assert round(p.boundary_m * 10, 6) == round(p.boundary_m * 10)  # 0.1 m grid
        fine = p.point in ("boundary", "boundary+1m", "boundary+2m")
        step = 0.1 if fine else 0.5
        assert round(p.vy_mps / step, 6) == round(p.vy_mps / step)
        assert p.ve0_mps == pytest.approx(p.ve0_kmh * KMH)
        assert p.vo0_mps == pytest.approx(p.vo0_kmh * KMH)
        assert p.vy_mps <= p.vo0_mps  # feasible lateral velocity
    cut_in = [p for p in pts if p.scenario == "cut-in"]
    assert {round(p.ve0_kmh - p.vo0_kmh) for p in cut_in} == {0, 20, 40}
    # boundary values are the C&C boundaries rounded up to 0.1 m
    one = next(p for p in cut_in if p.point == "boundary" and p.vo0_kmh < p.ve0_kmh)
    exact = cut_in_boundary(
        np.array([one.ve0_mps]), np.array([one.vo0_mps]), np.array([one.vy_mps])
    )[0]
    assert one.boundary_m == pytest.approx(np.ceil(exact * 10 - 1e-9) / 10)


def test_expected_verdicts(point_set):
    """Every point on or beyond the boundary is Preventable, the -5 m points are not, and
    the verdicts are what the evaluator says."""
    pts = point_set.points
    for p in pts:
        if p.offset_m is not None and p.offset_m >= 0:
            assert p.expected == "preventable" and p.must_not_collide
        if p.offset_m is not None and p.offset_m < 0:
            assert p.expected == "unpreventable"
    ci = [p for p in pts if p.scenario == "cut-in"]
    r = evaluate_cut_in(
        [p.ve0_mps for p in ci],
        [p.vo0_mps for p in ci],
        [p.dx0_m for p in ci],
        [p.vy_mps for p in ci],
    )
    assert [("unpreventable" if c else "preventable") for c in r.collision] == [
        p.expected for p in ci
    ]
    assert np.allclose(r.min_gap_m, [p.cc_min_gap_m for p in ci])
    co = [p for p in pts if p.scenario == "cut-out"]
    r = evaluate_cut_out([p.ve0_mps for p in co], [p.vy_mps for p in co], [p.dx0_f_m for p in co])
    assert r.valid.all() and not r.collision.any()


def test_skips_are_counted(point_set):
    skipped = point_set.skipped
    assert skipped["cut-out: lead would hit the stopped vehicle"] > 0
    assert skipped["cut-in: Vy infeasible at Vo0"] > 0  # Vo0 = 10 km/h with Vy > 2.78 m/s
    # 52+ km/h closing speed with the reaction waiting for TTC = 2 s: no Preventable gap, so
    # no points at all; by default (such cut-ins are not critical) every row has its points
    fast = R157Config(ve0_kmh=Grid(80, 80, 1), dv_kmh=Grid(60, 60, 1), scenarios=("cut-in",))
    wide = generate_points(fast, CCParams(above_ttc="wait"))
    assert wide.points == [] and wide.skipped["cut-in: no Preventable gap (boundary inf)"] > 0
    default = generate_points(fast)
    assert len(default.points) > 0
    assert default.skipped["cut-in: no Preventable gap (boundary inf)"] == 0
    aeb = generate_points(
        R157Config(ve0_kmh=Grid(80, 80, 1), dv_kmh=Grid(60, 60, 1), scenarios=("cut-in",)),
        CCParams(aeb=True),
    )
    assert len(aeb.points) > 0


def test_files_round_trip(point_set, tmp_path):
    csv_path = write_points_csv(point_set.points, tmp_path / "p.csv")
    json_path = write_points_json(point_set, tmp_path / "p.json")
    assert load_points(csv_path) == point_set.points
    assert load_points(json_path) == point_set.points
    doc = json.loads(json_path.read_text())
    assert doc["params"]["max_decel_g"] == 0.774 and doc["config"]["ve0_kmh"] == "30:90:30"
    header = csv_path.read_text().splitlines()[0].split(",")
    for column in (
        "scenario",
        "ve0_kmh",
        "ve0_mps",
        "vo0_kmh",
        "vo0_mps",
        "dx0_m",
        "vy_mps",
        "gx_max_g",
        "dx0_f_m",
        "boundary_m",
        "offset_m",
        "expected",
    ):
        assert column in header


@pytest.mark.parametrize(
    ("name", "text", "needle"),
    [
        ("bad.json", "{not json", "not valid JSON"),
        ("other.json", '{"format": "something"}', "not a hiyari-r157-points"),
        ("bad.csv", "id,scenario\nx,cut-in\n", "missing field"),
        ("missing.csv", None, "no such file"),
    ],
)
def test_broken_files_refused(tmp_path, point_set, name, text, needle):
    path = tmp_path / name
    if text is not None:
        path.write_text(text)
    with pytest.raises(HiyariError, match=needle):
        load_points(path)


def test_broken_values_refused(tmp_path, point_set):
    path = write_points_csv(point_set.points[:3], tmp_path / "p.csv")
    lines = path.read_text().splitlines()
    path.write_text("\n".join([lines[0], lines[1].replace(",preventable,", ",maybe,")]))
    with pytest.raises(HiyariError, match="line 2: expected must be"):
        load_points(path)
    path.write_text("\n".join([lines[0], lines[1].replace(",cut-in,", ",swerve,")]))
    with pytest.raises(HiyariError, match="unknown scenario"):
        load_points(path)


def test_point_tracks(point_set):
    t = np.arange(0, 12, 0.05)
    for scenario, names in (
        ("cut-in", {"other", "cc_ego"}),
        ("cut-out", {"lead", "stopped", "cc_ego"}),
        ("decel", {"lead", "cc_ego"}),
    ):
        p = next(q for q in point_set.points if q.scenario == scenario)
        tracks = point_tracks(p, t)
        assert set(tracks) == names
        assert tracks["cc_ego"].vx_mps[0] == pytest.approx(p.ve0_mps)


def _parser(module) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser()
    module.register(parser.add_subparsers(dest="command", required=True))
    return parser


def test_cli_points_and_boundary(tmp_path, capsys):
    args = _parser(cmd_r157).parse_args(
        [
            "r157",
            "points",
            "-o",
            str(tmp_path / "r157"),
            "--ve",
            "40:60:20",
            "--dv",
            "0:30:30",
            "--scenarios",
            "cut-in,decel",
            "--aeb",
        ]
    )
    assert args.func(args) == 0
    out = capsys.readouterr().out
    assert str(tmp_path / "r157" / "r157_points.csv") in out
    pts = load_points(tmp_path / "r157" / "r157_points.json")
    assert {p.scenario for p in pts} == {"cut-in", "decel"}
    assert json.loads((tmp_path / "r157" / "r157_points.json").read_text())["params"]["aeb"]
    args = _parser(cmd_boundary).parse_args(
        [
            "boundary",
            "cut-out",
            "-o",
            str(tmp_path / "b"),
            "--ve",
            "10:130:10",
            "--vy",
            "0.5:3:0.5",
            "--param",
            "max_decel_g=0.7",
        ]
    )
    assert args.func(args) == 0
    assert (tmp_path / "b" / "cut_out_boundary.png").stat().st_size > 10_000
    assert "cut_out_boundary.csv" in capsys.readouterr().out


def test_cli_bad_input_is_one_line(tmp_path, capsys):
    assert main(["boundary", "cut-in", "--vy", "0:3:0.5", "-o", str(tmp_path)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hiyari: error:") and "lateral velocity" in err[0]
    assert main(["r157", "points", "--scenarios", "merge", "-o", str(tmp_path)]) == 1
    assert "scenarios" in capsys.readouterr().err
    assert main(["r157", "points", "--param", "ramp_time_s=-1", "-o", str(tmp_path)]) == 1
    assert "ramp_time_s" in capsys.readouterr().err
