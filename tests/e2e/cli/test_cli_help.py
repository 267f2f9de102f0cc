"""The command line's options and help: defaults shown, options only where they apply."""

from __future__ import annotations

import pytest

from hiyari.bridge.cli.main import build_parser, main


def _help(capsys, *argv: str) -> str:  # noqa: ANN001
    with pytest.raises(SystemExit) as done:
        build_parser().parse_args([*argv, "--help"])
    assert done.value.code == 0
    return " ".join(capsys.readouterr().out.split())  # argparse wraps lines


def test_study_sct_help_shows_its_defaults(capsys) -> None:  # noqa: ANN001
    from hiyari.bridge.studies.sct.study import StudyConfig

    text = _help(capsys, "study", "sct")
    d = StudyConfig()
    assert f"simulated days per arm (default: {d.days})" in text
    assert f"SCT_safe, s (default: {d.controller.sct_safe})" in text
    assert f"independent runs (seeds) per arm (default: {d.runs})" in text
    assert "(default: None)" not in text and "(default: False)" not in text


def test_help_says_each_default_once(capsys) -> None:  # noqa: ANN001
    text = _help(capsys, "run")
    assert "--step-length STEP_LENGTH .xosc: step, s (default: 0.05)" in text
    # an option whose help already speaks of its default gets no second one
    assert "(default: on for a single run, off for a grid)" in text
    assert text.count("(default:") == text.lower().count("default")


@pytest.mark.parametrize(
    "scenario, foreign",
    [
        ("cut-in", ["--decel-perception", "never"]),
        ("cut-in", ["--cut-out-perception", "no"]),
        ("cut-out", ["--danger-at", "time"]),
        ("decel", ["--contact", "lane"]),
    ],
)
def test_boundary_takes_only_its_own_conventions(tmp_path, capsys, scenario, foreign) -> None:  # noqa: ANN001
    out = tmp_path / "b"
    assert main(["boundary", scenario, *foreign, "--ve", "60:60:1", "-o", str(out)]) == 1
    err = capsys.readouterr().err.strip()
    assert err == f"hiyari: error: unrecognized arguments: {' '.join(foreign)}"
    assert not out.exists()


def test_boundary_takes_its_own_conventions() -> None:
    parse = build_parser().parse_args
    assert parse(["boundary", "cut-in", "--danger-at", "overlap"]).danger_at == "overlap"
    assert parse(["boundary", "cut-out", "--cut-out-perception", "no"]).cut_out_perception == "no"
    assert parse(["boundary", "decel", "--decel-perception", "never"]).decel_perception == "never"


def test_sensors_render_takes_o() -> None:
    assert build_parser().parse_args(["sensors", "render", "-o", "frames"]).out == "frames"
