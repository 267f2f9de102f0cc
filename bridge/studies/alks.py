"""The ALKS acceptance table: every OpenSCENARIO file of a folder (the 15 openMSL ALKS
reference scenarios) run in closed loop with hiyari's default ego stack, per perception mode,
each recorded (run.mcap) with a static replay (replay.html), and the verdicts tabulated
(results.csv, results.md: the README's table).

    python -m hiyari.bridge.studies.alks ../shared/data/openscenario/alks -o out/alks

Runs go to worker processes (one libsumo simulation each); a re-run keeps the runs already
done (their result.json and replay.html), so an interrupted table resumes.
"""

from __future__ import annotations

import argparse
import csv
import json
import time
from dataclasses import dataclass
from pathlib import Path

from hiyari.atomic import atomic_path, write_text_atomic

#: Columns of results.csv (SI except where named).
COLUMNS = (
    "scenario",
    "perception",
    "verdict",
    "collided_with",
    "impact_speed_kmh",
    "min_ttc_s",
    "min_gap_m",
    "aeb_max_stage",
    "tested",
    "untested_cause",
    "near_misses",
    "min_vru_clearance_m",
    "min_vehicle_clearance_m",
    "false_activations",
    "stop_trigger",
    "sim_seconds",
    "wall_seconds",
)


@dataclass(frozen=True)
class AlksTask:
    """One run: scenario file, perception mode, output folder, replay frame stride."""

    path: Path
    perception: str
    out: Path
    replay_every: int = 20


def run_task(task: AlksTask) -> dict:
    """Run, record and export the replay of one scenario; its results.csv row."""
    from hiyari.bridge.loop.execute import RunOptions, execute
    from hiyari.bridge.loop.spec import EgoSetup
    from hiyari.bridge.loop.xosc_runs import load_plan
    from hiyari.bridge.record.reader import Recording
    from hiyari.bridge.replay.export import export_html
    from hiyari.bridge.studies.report.timeseries import plot_timeseries

    t0 = time.perf_counter()
    (run,) = load_plan(task.path, EgoSetup(perception=task.perception)).expand()
    with run.spec() as spec:
        res = execute(spec, RunOptions(out_dir=task.out, record=True, plot=plot_timeseries))
    rec = Recording.open(task.out / "run.mcap")
    export_html(
        rec,
        task.out / "replay.html",
        frames=range(0, len(rec), max(1, task.replay_every)),
        progress=False,
    )
    return row_of(task, res.as_dict(), time.perf_counter() - t0)


def row_of(task: AlksTask, d: dict, wall: float) -> dict:
    """The results.csv row of a run from its result summary (RunResult.as_dict())."""
    collision = bool(d["collision"])
    tested = bool(d.get("tested", True))
    near = int(d.get("near_misses", 0))
    verdict = "collision" if collision else "near miss" if near else "no collision"
    return {
        "scenario": task.path.stem.removesuffix("_template"),
        "perception": task.perception,
        "verdict": verdict if tested else "not tested",
        "collided_with": d["collided_with"],
        "impact_speed_kmh": d["impact_speed_kmh"] if collision else "",
        "min_ttc_s": "" if d["min_ttc_s"] is None else d["min_ttc_s"],
        "min_gap_m": "" if d["min_gap_m"] is None else d["min_gap_m"],
        "aeb_max_stage": d["aeb_max_stage"],
        "tested": tested,
        "untested_cause": d.get("untested_cause", ""),
        "near_misses": near,
        "min_vru_clearance_m": _cell(d.get("min_vru_clearance_m")),
        "min_vehicle_clearance_m": _cell(d.get("min_vehicle_clearance_m")),
        "false_activations": int(d.get("false_activations", 0)),
        "stop_trigger": d["stop_trigger"],
        "sim_seconds": round(d["sim_seconds"], 2),
        "wall_seconds": round(wall, 1),
    }


def _cell(x: object) -> object:
    return "" if x is None else x


def crashed_row(task: AlksTask, crash: object) -> dict:
    """The results.csv row of a run whose worker process died (``crash``: why)."""
    return {
        **dict.fromkeys(COLUMNS, ""),
        "scenario": task.path.stem.removesuffix("_template"),
        "perception": task.perception,
        "verdict": "crashed",
        "collided_with": str(crash),
    }


def finished_row(task: AlksTask) -> dict | None:
    """The row of a task whose outputs (result.json, replay.html) are already there."""
    result = task.out / "result.json"
    if not (result.is_file() and (task.out / "replay.html").is_file()):
        return None
    d = json.loads(result.read_text())["result"]
    return row_of(task, d, d["wall_seconds"])


def markdown(rows: list[dict]) -> str:
    """The table as Markdown: one line per scenario, the perception modes side by side."""
    modes = list(dict.fromkeys(r["perception"] for r in rows))
    by = {(r["scenario"], r["perception"]): r for r in rows}
    head = "| scenario | " + " | ".join(f"{m}: verdict, min TTC, min gap" for m in modes) + " |"
    lines = [head, "| --- |" + " --- |" * len(modes)]
    for name in dict.fromkeys(r["scenario"] for r in rows):
        cells = []
        for m in modes:
            r = by.get((name, m))
            if r is None:
                cells.append("not run")
                continue
            if r["verdict"] == "crashed":
                cells.append(f"**crashed** ({r['collided_with']}; run again to retry)")
                continue
            if r["verdict"] == "collision":
                verdict = f"**collision** ({r['collided_with']}, {r['impact_speed_kmh']} km/h)"
            elif r["verdict"] == "not tested":
                verdict = f"**not tested** ({r['untested_cause']})"
            elif r["verdict"] == "near miss":
                gaps = [r[k] for k in ("min_vru_clearance_m", "min_vehicle_clearance_m")]
                near = min(float(g) for g in gaps if g != "")
                verdict = f"**near miss** ({near} m)"
            else:
                verdict = "no collision"
            if int(r["false_activations"] or 0):
                verdict += f", {r['false_activations']} false activation(s)"
            ttc = f"{r['min_ttc_s']} s" if r["min_ttc_s"] != "" else "–"
            gap = f"{r['min_gap_m']} m" if r["min_gap_m"] != "" else "–"
            end = "" if r["stop_trigger"] else " (no stop trigger)"
            cells.append(f"{verdict}, {ttc}, {gap}{end}")
        lines.append(f"| {name.removeprefix('alks_scenario_')} | " + " | ".join(cells) + " |")
    lines.append("")
    for m in modes:
        sel = [r for r in rows if r["perception"] == m and r["verdict"] != "crashed"]
        n = {v: sum(r["verdict"] == v for r in sel) for v in ("collision", "near miss")}
        untested = sum(r["verdict"] == "not tested" for r in sel)
        false = sum(int(r["false_activations"] or 0) for r in sel)
        lines.append(
            f"{m}: {len(sel) - untested} tested, {untested} not tested; {n['collision']} "
            f"collisions, {n['near miss']} near misses; {false} false activations  "
        )
    return "\n".join(lines) + "\n"


def run_table(
    folder: Path,
    out: Path,
    perceptions: list[str],
    workers: int,
    only: str = "",
    run: bool = True,
) -> list[dict]:
    """Run every .xosc in ``folder`` per perception mode (runs whose outputs are already in
    ``out`` are kept; ``run`` False: only those); write results.csv / results.md. A run whose
    worker process dies is a "crashed" row (the reason in ``collided_with``), run again by
    the next call."""
    from tqdm import tqdm

    from hiyari.bridge.studies.pool import Crashed, PoolOptions, run_all

    files = sorted(p for p in folder.glob("*.xosc") if only in p.name)
    tasks = [AlksTask(p, m, out / p.stem / m) for m in perceptions for p in files]
    rows = [finished_row(t) for t in tasks]  # a re-run keeps the runs already done
    todo = [i for i, r in enumerate(rows) if r is None] if run else []
    with tqdm(total=len(tasks), initial=len(tasks) - len(todo), unit="run", desc="alks") as bar:
        for k, row in run_all(run_task, [tasks[i] for i in todo], PoolOptions(workers=workers)):
            rows[todo[k]] = crashed_row(tasks[todo[k]], row) if isinstance(row, Crashed) else row
            bar.update(1)
    done = [r for r in rows if r is not None]
    with atomic_path(out / "results.csv") as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(COLUMNS))
        w.writeheader()
        w.writerows(done)
    write_text_atomic(out / "results.md", markdown(done))
    return done


def main(argv: list[str] | None = None) -> int:
    """Command line: folder, -o out, --perception (repeatable), -j workers."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=Path, help="folder of .xosc files")
    ap.add_argument("-o", "--out", type=Path, default=Path("out/alks"))
    ap.add_argument(
        "--perception", action="append", choices=["perfect", "sensors", "none"], default=None
    )
    ap.add_argument("-j", "--workers", type=int, default=2)
    ap.add_argument("--only", default="", help="only files whose name contains this")
    ap.add_argument(
        "--no-run", action="store_true", help="tabulate the runs already in --out; run nothing"
    )
    args = ap.parse_args(argv)
    modes = args.perception or ["perfect", "sensors"]
    rows = run_table(args.folder, args.out, modes, args.workers, args.only, not args.no_run)
    print(markdown(rows))
    return 4 if any(r["verdict"] == "crashed" for r in rows) else 0  # 4: hiyari's RUNS_CRASHED


if __name__ == "__main__":
    raise SystemExit(main())
