"""The demo's catalogue stage: a few concrete runs per motorway cell, and the report (with the
perception coverage, written when missing, and the same run configuration as ``hiyari
evaluate`` writes, naming the demo command that ran)."""

from __future__ import annotations

import time
from pathlib import Path

from hiyari.bridge.studies.catalogue.evaluation.campaign import (
    CatalogueOptions,
    catalogue_cells,
    run_catalogue,
)
from hiyari.bridge.studies.catalogue.evaluation.provenance import run_configuration
from hiyari.bridge.studies.catalogue.evaluation.runner import RunConfig
from hiyari.bridge.studies.catalogue.structures import ensure_coverage
from hiyari.bridge.studies.pool import PoolOptions
from hiyari.bridge.studies.report.catalogue import verdict, write_report


def run_catalogue_demo(out: Path, runs_per_cell: int, workers: int, command: str) -> dict:
    """Run the motorway catalogue with perfect perception; write the report into ``out``.
    ``command``: the demo command that ran, for the report's run configuration."""
    options = CatalogueOptions(
        RunConfig(out / "roads"), runs_per_cell=runs_per_cell, pool=PoolOptions(workers)
    )
    t0 = time.perf_counter()
    rows = run_catalogue(options, out)
    wall = time.perf_counter() - t0
    structures = ensure_coverage(out / "structures")
    config = run_configuration(options, command, wall, structures)
    html = write_report(out, catalogue_cells("motorway"), rows, config, options.ranges, structures)
    prevent = [r for r in rows if r["preventable"] == "True"]
    return {
        "verdict": verdict(rows),
        "runs": len(rows),
        "passed": sum(r["passed"] == "True" for r in rows),
        "not_tested": sum(r["passed"] == "not tested" for r in rows),
        "preventable": len(prevent),
        "preventable_passed": sum(r["passed"] == "True" for r in prevent),
        "report": html,
    }
