"""Run a whole catalogue: every evaluated cell's concrete cases through the campaign pool
(local processes or Ray), each judged against the C&C expectation; resumable.

Results go to ``<out>/results.csv``, one row per concrete run keyed by ``run_id``; a row is
appended (one write, flushed) as soon as its run finishes, so a killed campaign keeps what
finished and a new one runs only the missing rows. When every row is in, the table is rewritten
in plan order (workers finish in any order), so the same inputs give the same file; only the
``wall_s`` column (each run's wall time) varies. Failed runs are then re-run with an MCAP
recording (``<out>/recordings/<run_id>.mcap``; runs are deterministic, so the recording is
the failing run) and its static replay page (``<run_id>.html``).

A run that did not test its disturbance (the ego braked hard, stopped or left its lane before
it: hiyari.risk.metrics.tested) has ``passed = "not tested"`` and the reason in ``cause``: it
is neither passed nor failed.

A run whose worker process dies (a native crash, an out-of-memory kill) gets a row with
``passed = "crashed"`` and the signal in ``cause``; the other runs go on, and the same
command again runs it anew (its new row replaces the crashed one).
"""

from __future__ import annotations

import contextlib
import csv
import io
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from hiyari.atomic import append_bytes, write_text_atomic
from hiyari.bridge.loop.drivers.cc_driver import cc_reference_stack
from hiyari.bridge.loop.execute import RunOptions, execute
from hiyari.bridge.studies.catalogue.evaluation.expectation import Expectation, annex_g, judge
from hiyari.bridge.studies.catalogue.evaluation.runner import RunConfig, case_spec, prepare_road
from hiyari.bridge.studies.catalogue.space.concrete import ConcreteCase, concrete_cases
from hiyari.bridge.studies.catalogue.space.obstruction import Cell, expand
from hiyari.bridge.studies.catalogue.space.parameters import Ranges
from hiyari.bridge.studies.catalogue.space.taxonomy import (
    Geometry,
    chain_combinations,
    general_combinations,
    motorway_combinations,
)
from hiyari.bridge.studies.pool import Crashed, PoolOptions, run_all
from hiyari.errors import HiyariError, WriteFailed

_log = logging.getLogger(__name__)

CATALOGUES = ("motorway", "general")
COLUMNS = (
    "run_id", "cell", "combination", "geometry", "ego_motion", "position", "motion", "lanes",
    "params", "collision", "collided_with", "impact_mps", "min_gap_m", "min_ttc_s",
    "aeb_first_s", "collision_time_s", "cc_collision", "cc_impact_mps", "cc_source",
    "preventable", "passed", "cause", "tested", "false_activations", "near_misses",
    "min_vru_clearance_m", "wall_s",
)  # fmt: skip
#: ``passed`` of a run that did not test its disturbance (hiyari.risk.metrics.tested): neither
#: passed nor failed, whatever it collided with.
NOT_TESTED = "not tested"


@dataclass(frozen=True)
class CatalogueOptions:
    """A catalogue campaign: which catalogue, how many concrete runs per evaluated cell, the
    seed of the sampling, how each run goes and where the runs go."""

    run: RunConfig
    catalogue: str = "motorway"
    runs_per_cell: int = 14
    seed: int = 0
    pool: PoolOptions = field(default_factory=PoolOptions)
    ranges: Ranges = field(default_factory=Ranges)
    record_failures: bool = True
    #: run only cells whose key starts with one of these (e.g. "M03", "M02-front"); () = all
    only: tuple[str, ...] = ()

    def validate(self) -> None:
        if self.catalogue not in CATALOGUES:
            raise HiyariError(
                f"--catalogue: one of {', '.join(CATALOGUES)}, got {self.catalogue!r}"
            )
        if self.runs_per_cell < 1:
            raise HiyariError(f"--runs-per-cell must be >= 1, got {self.runs_per_cell}")
        if self.run.perception not in ("perfect", "sensors", "none"):
            raise HiyariError(
                f"--perception: perfect, sensors or none, got {self.run.perception!r}"
            )
        self.pool.validate()


def catalogue_cells(catalogue: str, ranges: Ranges | None = None) -> list[Cell]:
    """Every expansion of the catalogue's combinations (motorway: the 24 of Fig. 48; general:
    the general-road extension), plus the §4.1.3 chains, with their verdicts."""
    combos = motorway_combinations() if catalogue == "motorway" else general_combinations()
    return [cell for c in [*combos, *chain_combinations()] for cell in expand(c, ranges)]


def supported(cell: Cell) -> bool:
    """Whether hiyari runs this cell's concrete cases (intersection runs: not yet)."""
    return cell.valid and cell.combination.geometry != Geometry.INTERSECTION


def plan(options: CatalogueOptions, cells: list[Cell]) -> list[ConcreteCase]:
    """The concrete cases of every evaluated, supported cell."""
    chosen = [
        cell
        for cell in cells
        if supported(cell) and (not options.only or cell.key.startswith(options.only))
    ]
    if options.only and not chosen:
        raise HiyariError(f"--cells {','.join(options.only)}: no evaluated cell matches")
    return [
        case
        for cell in chosen
        for case in concrete_cases(cell, options.runs_per_cell, options.seed, options.ranges)
    ]


def case_by_id(run_id: str, catalogue: str = "motorway", seed: int = 0,
               ranges: Ranges | None = None) -> ConcreteCase:  # fmt: skip
    """The concrete case a results row names (the Sobol samples are a fixed sequence, so the
    i-th case does not depend on how many runs per cell were asked for)."""
    key, _, index = run_id.rpartition("-")
    cell = next((c for c in catalogue_cells(catalogue, ranges) if c.key == key), None)
    if cell is None or not index.isdigit() or not supported(cell):
        raise HiyariError(f"no concrete case {run_id!r} in the {catalogue} catalogue")
    return concrete_cases(cell, int(index) + 1, seed, ranges)[int(index)]


def _cause(res: object, expected: Expectation) -> str:
    """One line on why a run failed."""
    what = f"hit {res.collided_with} at {res.relative_impact_speed:.1f} m/s"
    cc = "the C&C driver avoids it" if expected.preventable else (
        f"the C&C driver hits at {expected.impact_speed:.1f} m/s")  # fmt: skip
    if res.aeb_first_time != res.aeb_first_time:  # nan: never braked by AEB
        how = "the stack never triggered its AEB"
    else:
        how = f"AEB from t = {res.aeb_first_time:.2f} s, contact at {res.collision_time:.2f} s"
    return f"{what} ({how}); {cc}"


def run_row(task: tuple[ConcreteCase, RunConfig]) -> dict:
    """Run one concrete case with the stack under test, get the C&C expectation (closed form,
    or the reference driver's run) and judge it: one results row."""
    case, config = task
    t0 = time.perf_counter()
    res = execute(case_spec(case, config))
    expected = annex_g(case)
    if expected is None:
        ref = execute(case_spec(case, config, cc_reference_stack))
        expected = Expectation(ref.collision, ref.relative_impact_speed if ref.collision else 0.0,
                               "reference")  # fmt: skip
    impact = res.relative_impact_speed if res.collision else 0.0
    tested = res.tested()
    passed = judge(res.collision, impact, expected) if tested.tested else NOT_TESTED
    return {
        **_case_columns(case),
        "collision": res.collision,
        "collided_with": res.collided_with or "",
        "impact_mps": round(impact, 3),
        "min_gap_m": round(res.min_gap, 3),
        "min_ttc_s": round(res.min_ttc, 3),
        "aeb_first_s": round(res.aeb_first_time, 3),
        "collision_time_s": round(res.collision_time, 3),
        "cc_collision": expected.collision,
        "cc_impact_mps": round(expected.impact_speed, 3),
        "cc_source": expected.source,
        "preventable": expected.preventable,
        "passed": passed,
        "cause": tested.reason if not tested.tested else "" if passed else _cause(res, expected),
        "tested": tested.tested,
        "false_activations": res.false_activations(),
        "near_misses": len(res.near_misses()),
        "min_vru_clearance_m": round(res.min_clearance(True), 3),
        "wall_s": round(time.perf_counter() - t0, 3),
    }


def _case_columns(case: ConcreteCase) -> dict:
    """The columns that name a case: its id, cell, combination and parameters."""
    c = case.cell.combination
    return {
        "run_id": case.run_id,
        "cell": case.cell.key,
        "combination": c.key,
        "geometry": c.geometry.value,
        "ego_motion": c.ego.value,
        "position": case.cell.position.value,
        "motion": c.motion.value,
        "lanes": case.cell.lanes,
        "params": ";".join(f"{k}={v:.4g}" for k, v in case.params.items()),
    }


def crashed_row(case: ConcreteCase, crash: Crashed) -> dict:
    """The row of a run whose worker process died: the case, its parameters, the signal."""
    return {
        **dict.fromkeys(COLUMNS, ""),
        **_case_columns(case),
        "passed": "crashed",
        "cause": str(crash),
        "wall_s": 0.0,  # not empty: an empty wall_s marks a line cut short
    }


def read_results(path: Path) -> dict[str, dict]:
    """Rows of a results table by run_id (a line cut short by a kill is skipped)."""
    if not path.is_file():
        return {}
    rows = {}
    with path.open(newline="") as f:
        for row in csv.DictReader(f):
            if None in row.values() or None in row or row.get("wall_s", "") == "":
                continue
            rows[row["run_id"]] = row
    return rows


def _drop_partial_line(path: Path) -> None:
    """Cut a last line left unfinished by a killed campaign, so appends start on a new line."""
    if not path.is_file():
        return
    data = path.read_bytes()
    if data and not data.endswith(b"\n"):
        with path.open("r+b") as f:
            f.truncate(data.rfind(b"\n") + 1)


def _line(row: dict) -> str:
    buf = io.StringIO()
    csv.DictWriter(buf, COLUMNS, lineterminator="\n").writerow(row)
    return buf.getvalue()


def run_catalogue(options: CatalogueOptions, out: Path,
                  on_progress: Callable[[int, int], None] | None = None) -> list[dict]:  # fmt: skip
    """Run every missing concrete case of the catalogue into ``out/results.csv``; return all
    rows of the planned cases (done before and now). ``on_progress(done, total)``."""
    options.validate()
    cells = catalogue_cells(options.catalogue, options.ranges)
    cases = plan(options, cells)  # a bad cell selection is refused before anything is made
    out.mkdir(parents=True, exist_ok=True)
    for geometry, lanes in sorted(
        {(c.cell.combination.geometry.value, c.cell.lanes) for c in cases}
    ):
        prepare_road(options.run.roads, geometry, lanes)
    table = out / "results.csv"
    _drop_partial_line(table)
    done = read_results(table)
    todo = [c for c in cases if done.get(c.run_id, {}).get("passed", "crashed") == "crashed"]
    if not table.is_file() or table.stat().st_size == 0:
        append_bytes(table, (",".join(COLUMNS) + "\n").encode())
    count = len(cases) - len(todo)
    if on_progress:
        on_progress(count, len(cases))
    tasks = [(c, options.run) for c in todo]
    with contextlib.closing(run_all(run_row, tasks, options.pool)) as results:
        try:
            for i, row in results:
                if isinstance(row, Crashed):
                    row = crashed_row(todo[i], row)
                append_bytes(table, _line(row).encode())
                done[row["run_id"]] = {k: str(v) for k, v in row.items()}
                count += 1
                if on_progress:
                    on_progress(count, len(cases))
        except (KeyboardInterrupt, WriteFailed) as exc:  # Ctrl-C, SIGTERM or a full disk
            results.close()  # the workers stop
            resume = (
                f"{count} of {len(cases)} runs are kept in {table}; run the same command "
                "again to resume"
            )
            if isinstance(exc, WriteFailed):
                raise WriteFailed(f"{exc}; {resume}") from None
            exc.args = (resume,)
            raise
    _sort_table(table, [c.run_id for c in cases])
    if options.record_failures:
        try:
            record_failures(options, cases, done, out / "recordings")
        except KeyboardInterrupt as exc:
            exc.args = (
                f"all {len(cases)} runs are kept in {table}, not all recordings of failed runs "
                "(an unfinished one keeps its .part name); run the same command again to "
                "record them",
            )
            raise
    return [done[c.run_id] for c in cases]


def _sort_table(path: Path, order: list[str]) -> None:
    """Rewrite the results table with the rows of ``order`` first, in that order, then any other
    rows (from campaigns with other options) by run_id; atomically."""
    rows = read_results(path)
    rank = {run_id: k for k, run_id in enumerate(order)}
    ids = sorted(rows, key=lambda r: (rank.get(r, len(rank)), r))
    buf = io.StringIO()
    writer = csv.DictWriter(buf, COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows[r] for r in ids)
    write_text_atomic(path, buf.getvalue())


def _record(task: tuple[ConcreteCase, RunConfig, Path]) -> str:
    """Record the case unless its recording exists, then its static replay page beside it."""
    from hiyari.bridge.record.reader import Recording
    from hiyari.bridge.replay.export import export_html

    case, config, path = task  # no camera images: the failure is in the stack's outputs
    if not path.is_file():
        execute(case_spec(case, config), RunOptions(recording=path, camera_image_every=0))
    page = path.with_suffix(".html")
    if not page.is_file():
        export_html(Recording.open(path), page, progress=False)
    return str(path)


def record_failures(options: CatalogueOptions, cases: list[ConcreteCase], rows: dict[str, dict],
                    folder: Path) -> None:  # fmt: skip
    """Re-run each failed case with an MCAP recording and write its static replay page
    (``<run_id>.html``, the report links it), unless they exist. A recording whose worker
    dies is skipped with a warning (the row stands; the next call records it)."""
    failed = [c for c in cases if rows[c.run_id]["passed"] in ("False", False)]
    todo = [(c, options.run, folder / f"{c.run_id}.mcap") for c in failed]
    todo = [t for t in todo if not (t[2].is_file() and t[2].with_suffix(".html").is_file())]
    for i, result in run_all(_record, todo, options.pool):
        if isinstance(result, Crashed):
            _log.warning(
                "%s: not recorded, %s; run the same command again to record it",
                todo[i][2],
                result,
            )
