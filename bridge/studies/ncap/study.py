"""``hiyari ncap``: every test point of the Euro NCAP 2023 AEB protocols' grids, run on the
campaign pool (bridge.studies.pool: local processes or Ray) and scored.

Plan: each test's Variations file is read and checked with the ego setup before anything is
written (a missing file, a bad stack or preset is one line); night tests run again at night
with the ego's low beams. Results stream to ``out/results.csv`` as points finish (one flushed
row per point), so an interrupted study keeps its rows and a rerun resumes; the table is
rewritten sorted at the end. Points that lost points are run again recorded
(``recordings/<point>.mcap``; runs are deterministic, so the recording is that run), and their
replays exported (``replays/<point>.html``).
"""

from __future__ import annotations

import csv
import json
import shutil
import tempfile
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

from hiyari.atomic import atomic_path, write_text_atomic
from hiyari.bridge.loop.spec import EgoSetup
from hiyari.bridge.loop.xosc_runs import load_plan
from hiyari.bridge.studies.ncap import scoring
from hiyari.bridge.studies.ncap.points import COLUMNS, NcapPoint, run_point, score_row, simulate
from hiyari.bridge.studies.ncap.protocols import (
    PROTOCOL_NAMES,
    NcapTest,
    default_root,
    select_tests,
    variations_file,
)
from hiyari.bridge.studies.ncap.stack import stack_factory
from hiyari.bridge.studies.pool import PoolOptions, run_all
from hiyari.errors import HiyariError

#: The disturbance preset of night tests: night, the ego's low beams on.
NIGHT_PRESET = "night_headlights"


@dataclass(frozen=True)
class NcapOptions:
    """What to run and how. ``only``: test keys (empty: every test of ``protocol``);
    ``speeds``: test speeds (km/h) to keep on the grids' speed rows (empty: all) - a reduced
    grid, for quick looks and tests; ``environment``: the day tests' preset."""

    out_dir: Path
    protocol: str = "all"
    perception: str = "perfect"
    environment: str = "clear"
    stack: str = ""
    files: Path = field(default_factory=default_root)
    only: tuple[str, ...] = ()
    speeds: tuple[float, ...] = ()
    step_length: float = 0.05
    #: s of scenario time after which a test ends: a test ends at contact or when its file's
    #: stop trigger fires, but a reversing ego the AEB stopped short of the child waits for
    #: a trigger that never comes (the longest tests take 18 s)
    max_duration: float = 40.0
    pool: PoolOptions = field(default_factory=PoolOptions)
    replays: bool = True


@dataclass
class NcapResult:
    """A finished study: its rows by point id, the scored points and the protocol totals."""

    tests: list[NcapTest]
    rows: dict[str, dict]
    points: dict[str, scoring.PointScore]
    protocols: list[scoring.ProtocolScore]
    ran: int
    kept: int


def plan(options: NcapOptions) -> list[NcapPoint]:
    """Every test point, checked (files, parameters, stack, presets); nothing is written."""
    from hiyari.sensors.environment.presets import disturbance_preset

    tests = select_tests(options.protocol, options.only)
    for preset in (options.environment, NIGHT_PRESET):
        try:
            disturbance_preset(preset)
        except HiyariError as exc:
            raise HiyariError(f"--environment: {exc}") from None
    stack_factory(options.stack)  # a bad --stack fails here, before any run
    points = []
    for test in tests:
        path = variations_file(options.files, test)
        for lighting in test.lightings:
            env = options.environment if lighting == "day" else NIGHT_PRESET
            setup = EgoSetup(
                perception=options.perception,
                environment=env,
                step_length=options.step_length,
                max_duration=options.max_duration,
            )
            for run in load_plan(path, setup).expand():
                if options.speeds and not _kept_speed(test, run.params, options.speeds):
                    continue
                if test.lighting_param and _lighting(run.params, test) != lighting:
                    continue
                pid = f"{test.key}-{lighting}-{run.index:03d}"
                points.append(NcapPoint(pid, test, lighting, run, options.stack))
    if not points:
        raise HiyariError(f"--speeds {_speeds(options.speeds)}: no test point has these speeds")
    return points


def _lighting(params: dict[str, str], test: NcapTest) -> str:
    """'night' when the run's own lighting parameter says Night, else 'day'."""
    value = str(params.get(test.lighting_param or "", "")).strip().lower()
    return "night" if value == "night" else "day"


def _speeds(speeds: tuple[float, ...]) -> str:
    return ",".join(f"{s:g}" for s in speeds)


def _kept_speed(test: NcapTest, params: dict[str, str], speeds: tuple[float, ...]) -> bool:
    value = params.get("Ego_speed_kph")
    return value is None or any(abs(float(value) - s) < 1e-6 for s in speeds)


def _with_roads(points: list[NcapPoint], folder: Path) -> list[NcapPoint]:
    """The points with each scenario road imported once into ``folder``."""
    from dataclasses import replace

    from hiyari.bridge.loop.spec import import_road

    nets: dict[Path, Path] = {}
    out = []
    for p in points:
        sc = p.run.load()
        xodr = sc.road_network
        if xodr not in nets:
            nets[xodr] = import_road(sc, folder)
        out.append(replace(p, run=replace(p.run, road_net=(xodr, nets[xodr]))))
    return out


def _identity(options: NcapOptions) -> dict:
    """What the rows of a study depend on: a folder resumes only the same study."""
    return {
        "stack": options.stack or "hiyari NCAP stack",
        "perception": options.perception,
        "environment": options.environment,
        "step_length": options.step_length,
        "max_duration": options.max_duration,
        "files": str(Path(options.files).resolve()),
    }


def _check_same_study(out: Path, options: NcapOptions) -> None:
    """HiyariError when ``out`` holds the rows of a study run with other settings."""
    path = out / "study.json"
    if not path.is_file():
        return
    before, now = json.loads(path.read_text()), _identity(options)
    diff = [k for k in now if before.get(k) != now[k]]
    if diff:
        k = diff[0]
        raise HiyariError(
            f"{out}: its results were made with {k} {before.get(k)!r}, not {now[k]!r}; "
            "use another folder"
        )


def read_rows(path: Path) -> dict[str, dict]:
    """Rows of an existing results.csv by point id (a torn last line is ignored)."""
    if not path.exists():
        return {}
    rows = {}
    with path.open(newline="") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames is not None and tuple(reader.fieldnames) != COLUMNS:
            raise HiyariError(f"{path}: not a 'hiyari ncap' results table; use another folder")
        for row in reader:
            if None in row or any(v is None for v in row.values()) or not row.get("status"):
                continue
            rows[row["point_id"]] = row
    return rows


def _write_rows(path: Path, rows: list[dict]) -> None:
    with atomic_path(path) as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: _fmt(r.get(k, "")) for k in COLUMNS})


def _fmt(v: object) -> str:
    return "" if v is None else str(v)


def run_study(
    options: NcapOptions, progress: Callable[[int, int], None] | None = None
) -> NcapResult:
    """Run every point not yet in ``out/results.csv``; score all; record the points that lost
    points. ``progress(done, total)`` after each point."""
    points = plan(options)
    out = options.out_dir
    table = out / "results.csv"
    done = read_rows(table)  # a foreign table is refused before anything is written
    _check_same_study(out, options)
    out.mkdir(parents=True, exist_ok=True)
    write_text_atomic(out / "study.json", json.dumps(_identity(options), indent=1) + "\n")
    points = _with_roads(points, out / "roads")
    by_id = {p.point_id: p for p in points}
    keep = {k: r for k, r in done.items() if k in by_id and r["status"] == "ok"}
    todo = [p for p in points if p.point_id not in keep]
    _write_rows(table, [keep[p.point_id] for p in points if p.point_id in keep])
    if progress:
        progress(len(keep), len(points))
    with table.open("a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        try:
            for _, row in run_all(run_point, todo, options.pool):
                writer.writerow({k: _fmt(row.get(k, "")) for k in COLUMNS})
                f.flush()
                keep[row["point_id"]] = row
                if progress:
                    progress(len(keep), len(points))
        except KeyboardInterrupt as exc:
            f.flush()
            exc.args = (
                f"{len(read_rows(table))} of {len(points)} test points are kept in {table}; "
                "run the same command again to resume",
            )
            raise
    rows = {p.point_id: keep[p.point_id] for p in points}
    _write_rows(table, list(rows.values()))
    scored = {pid: score_row(by_id[pid].test, r) for pid, r in rows.items()}
    lost = [p for p in points if _lost(scored[p.point_id])]
    record_lost(lost, out, options)
    tests = select_tests(options.protocol, options.only)
    return NcapResult(
        tests, rows, scored, totals(tests, scored.values(), options.protocol), len(todo),
        len(points) - len(todo),
    )  # fmt: skip


def activation_counts(rows: Iterable[dict]) -> tuple[int, int]:
    """(near misses, false activations) summed over the results rows (their runs that ran)."""
    near = false = 0
    for r in rows:
        if r.get("status") == "ok":
            near += int(r.get("near_misses") or 0)
            false += int(r.get("false_activations") or 0)
    return near, false


def _lost(p: scoring.PointScore) -> bool:
    return p.colour is not None and p.colour is not scoring.Colour.GREEN


def totals(tests: list[NcapTest], points: object, protocol: str) -> list[scoring.ProtocolScore]:
    """The protocol totals of the scored points (every protocol ``protocol`` names that has a
    test in ``tests``)."""
    pts = list(points)  # type: ignore[call-overload]
    out = []
    for name in PROTOCOL_NAMES if protocol == "all" else (protocol,):
        mine = [t for t in tests if t.protocol == name]
        scenarios = list(dict.fromkeys(t.scenario_key for t in mine))
        if mine:
            out.append(
                scoring.protocol_score(
                    name,
                    (scoring.scenario_score(
                        s, sum(t.max_points for t in mine if t.scenario_key == s), pts)
                     for s in scenarios),
                )
            )  # fmt: skip
    return out


def _record(task: tuple[NcapPoint, Path, bool]) -> str:
    """Run a point again recorded; move its recording to ``target``; export its replay."""
    point, target, replay = task
    if not target.is_file():
        with tempfile.TemporaryDirectory(prefix="hiyari-ncap-") as tmp:
            simulate(point, Path(tmp) / "run")
            target.parent.mkdir(parents=True, exist_ok=True)
            with atomic_path(target) as part:
                shutil.move(Path(tmp) / "run" / "run.mcap", part)
    html = target.parent.parent / "replays" / f"{point.point_id}.html"
    if replay and not html.is_file():
        from hiyari.bridge.record.reader import Recording
        from hiyari.bridge.replay.export import export_html

        html.parent.mkdir(parents=True, exist_ok=True)
        export_html(Recording(target), html, progress=False)
    return point.point_id


def record_lost(points: list[NcapPoint], out: Path, options: NcapOptions) -> None:
    """Recording (and replay) of each point that lost points, unless it has them."""
    todo = [(p, out / "recordings" / f"{p.point_id}.mcap", options.replays) for p in points]
    todo = [
        t for t in todo
        if not t[1].is_file() or (t[2] and not (out / "replays" / f"{t[0].point_id}.html").is_file())
    ]  # fmt: skip
    for _ in run_all(_record, todo, options.pool):
        pass
