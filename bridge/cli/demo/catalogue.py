"""The demo's catalogue stage: a few concrete runs per motorway cell, and the report."""

from __future__ import annotations

from pathlib import Path

from hiyari.bridge.studies.catalogue.evaluation.campaign import (
    CatalogueOptions,
    catalogue_cells,
    run_catalogue,
)
from hiyari.bridge.studies.catalogue.evaluation.runner import RunConfig
from hiyari.bridge.studies.pool import PoolOptions
from hiyari.bridge.studies.report.catalogue import write_report


def run_catalogue_demo(out: Path, runs_per_cell: int, workers: int) -> dict:
    """Run the motorway catalogue with perfect perception; write the report into ``out``."""
    options = CatalogueOptions(
        RunConfig(out / "roads"), runs_per_cell=runs_per_cell, pool=PoolOptions(workers)
    )
    rows = run_catalogue(options, out)
    config = {
        "command": f"hiyari evaluate --runs-per-cell {runs_per_cell} -o {out}",
        "stack": "hiyari default",
        "perception": "perfect",
        "runs per cell": runs_per_cell,
    }
    html = write_report(out, catalogue_cells("motorway"), rows, config, options.ranges)
    prevent = [r for r in rows if r["preventable"] == "True"]
    return {
        "runs": len(rows),
        "passed": sum(r["passed"] == "True" for r in rows),
        "preventable": len(prevent),
        "preventable_passed": sum(r["passed"] == "True" for r in prevent),
        "report": html,
    }
