"""The SCT study's report for a short run (issue 36): no "nan%", no reference to a section it
does not have, valid JSON, and figures whose titles do not overlap, whose count axes start at
0, and which keep the seed's 2-day counts off the axis of a short run. Synthetic arm results
(the study itself is tested in test_sct_study)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from hiyari.bridge.studies.report.sct import (
    encounters_figure,
    incidents_figure,
    timeline_figure,
    write_report,
)
from hiyari.bridge.studies.sct.study import ARMS, ArmResult, StudyConfig
from hiyari.bridge.studies.sct.summary import change_text, summarise
from hiyari.risk.metrics.incidents import Encounter

SHORT = StudyConfig(days=0.002, runs=2)


def _results(config: StudyConfig, incidents: dict[str, int]) -> list[ArmResult]:
    out = []
    for arm in ARMS:
        for run in range(config.runs):
            n = incidents.get(arm, 0) if run == 0 else 0
            enc = [Encounter(f"v{k}", f"p{k}", 1.0, time=30.0 * k + 5.0, min_ttc=1.0,
                             min_sct=1.2) for k in range(n)]  # fmt: skip
            out.append(ArmResult("unsignalised", arm, run, 1 + run, config.run_seconds, 1.0, 10,
                                 10, enc, np.ones(n, bool), np.full(3, 25.0), np.full(3, 1.6),
                                 np.full(2, 5.0)))  # fmt: skip
    return out


def test_short_run_without_baseline_incidents(tmp_path: Path) -> None:
    report = write_report(tmp_path, SHORT, _results(SHORT, {}), 12.0)
    text = report.read_text()
    assert "nan" not in text.lower()
    assert "sensitivity section" not in text and "--sensitivity HOURS" not in text
    assert "No baseline incidents in unsignalised over 0.002 simulated days" in text
    assert "falls short" not in text and "reaches the seed" not in text
    summary = json.loads((tmp_path / "summary.json").read_text(), parse_constant=_no_nan)
    assert summary["reduction"] == {"unsignalised": None}
    assert change_text(float("nan")) == "n/a (no baseline incidents)"
    assert change_text(0.5) == "-50%"


def test_short_of_the_seed_points_to_the_sensitivity_option(tmp_path: Path) -> None:
    text = write_report(tmp_path, SHORT, _results(SHORT, {"baseline": 4, "sct": 2}), 1.0)
    body = text.read_text()
    assert "| hiyari, unsignalised | 4 | 2 | 50% |" in body
    assert "falls short of the seed's 68% for: unsignalised (50%)" in body
    assert "`--sensitivity HOURS` adds a section" in body


def test_figures_of_a_short_run(tmp_path: Path) -> None:
    results = _results(SHORT, {"baseline": 4, "sct": 2})
    figures = [incidents_figure(SHORT, summarise(SHORT, results)),
               encounters_figure(SHORT, results), timeline_figure(SHORT, results)]  # fmt: skip
    for fig in figures:
        renderer = FigureCanvasAgg(fig).get_renderer()
        fig.draw(renderer)
        boxes = [ax.title.get_window_extent(renderer) for ax in fig.axes if ax.get_title()]
        for i, a in enumerate(boxes):
            assert not any(a.overlaps(b) for b in boxes[i + 1 :]), "titles overlap"
        for ax in fig.axes:
            assert ax.get_ylim()[0] == 0.0, ax.get_title()
    # the seed's 2-day counts and the short run's are on separate axes
    seed, ours = figures[0].axes
    assert "2 simulated days" in seed.get_title() and "0.002" in ours.get_title()
    assert seed.get_ylim()[1] > 1990 and ours.get_ylim()[1] < 20
    # a 2.9-minute study is counted per minute, its axis ends with the study
    timeline = figures[2].axes[0]
    assert "minute" in timeline.get_title()
    assert timeline.get_xlim()[1] == pytest.approx(0.002 * 1440)


def _no_nan(name: str) -> float:
    raise AssertionError(f"{name} in summary.json")
