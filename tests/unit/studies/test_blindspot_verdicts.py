"""The blind-spot page counts runs tested and not tested, collisions and near misses of the
tested ones and false activations (issue 30, items 1, 4 and 5)."""

from __future__ import annotations

from dataclasses import replace

from hiyari.bridge.studies.perception.blindspot.catalogue import combinations
from hiyari.bridge.studies.perception.blindspot.run import CaseResult
from hiyari.bridge.studies.report.blindspot import catalogue_markdown, verdict_counts


def test_blindspot_page_counts_not_tested_near_misses_and_false_activations():
    combo = next(c for c in combinations() if c.realisable)
    ran = CaseResult(combo, 0.0, 0.1, False, 5.0, 0, "", True, "", 0, 0)
    phantom = replace(ran, aeb_max_stage=3, tested=False, false_activations=2,
                      untested_cause="braked at 0.40 s, before the disturbance at 1.50 s")  # fmt: skip
    close = replace(ran, near_misses=1, false_activations=1)
    not_run = CaseResult(combo, 0.0, 0.1, None, None, None)
    line = verdict_counts([ran, phantom, close, not_run])
    assert line == (
        "Closed loop: 3 runs, 2 tested, 1 not tested; 0 collisions, 1 near misses; false "
        "activations in 2 of 3 runs (3 in all)."
    )
    md = catalogue_markdown([phantom, close])
    assert "NOT TESTED (braked at 0.40 s" in md and "NEAR MISS" in md
