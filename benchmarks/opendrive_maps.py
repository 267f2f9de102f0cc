"""Third-party OpenDRIVE maps: how many import, and how many carry generated traffic for 60 s.

For every .xodr in DIR (maps written by other tools, kept outside the repository): import it
with ``import_opendrive`` (repair pre-pass, lane-type table, junction-shape choice), generate
demand with ``write_demand`` (vehicles; persons where the map has sidewalks) and run it for
``--seconds`` simulated seconds on real SUMO. Each map runs in its own process (libsumo runs
one simulation per process, and a crash of one map must not end the benchmark).

Baseline, in the same run: plain netconvert with the options the import used before the lane
table and the repair pre-pass (``--opendrive.internal-shapes true``, SUMO's own type map):
the share of maps it converts at all.

Printed per map: import outcome (repairs, shape choice), traffic outcome (vehicles and
persons seen, collision pairs, vehicle-steps on lanes closed to ordinary traffic), or the
failure with its cause; then the totals as percentages; a PNG bar chart when ``--png``.

Run: .venv/bin/python benchmarks/opendrive_maps.py /work/thirdparty/opendrive [--png out.png]
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import multiprocessing
import resource
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from tqdm import tqdm

from hiyari.errors import HiyariError
from hiyari.net.road.geometry import RoadGeometry
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.sumo_tools import sumo_binary, sumo_env
from hiyari.traffic import DemandConfig, SimConfig, Simulation, write_demand


@dataclass
class MapResult:
    """What happened to one map."""

    name: str
    imported: bool = False
    baseline_imported: bool = False
    traffic: bool = False
    warnings: list[str] = field(default_factory=list)
    vehicles: int = 0
    persons: int = 0
    collisions: int = 0
    closed_lane_steps: int = 0  # ordinary vehicle-steps on lanes closed to them
    error: str = ""


#: Memory and time granted to the baseline netconvert run (it exhausts memory on some maps).
BASELINE_MEMORY = 4 << 30
BASELINE_SECONDS = 120


def _limit_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (BASELINE_MEMORY, BASELINE_MEMORY))


def _baseline(xodr: Path, tmp: Path) -> bool:
    args = [str(sumo_binary("netconvert")), "--opendrive-files", str(xodr),
            "--offset.disable-normalization", "true", "--no-turnarounds", "true",
            "--opendrive.internal-shapes", "true", "-o", str(tmp / "baseline.net.xml")]  # fmt: skip
    try:
        proc = subprocess.run(args, capture_output=True, env=sumo_env(), preexec_fn=_limit_memory,
                              timeout=BASELINE_SECONDS)  # fmt: skip
    except subprocess.TimeoutExpired:
        return False
    return proc.returncode == 0


def _traffic(net: Path, tmp: Path, seconds: float, r: MapResult) -> None:
    g = RoadGeometry.from_net(net)
    closed = {ln.id for ln in g.lanes.values() if "passenger" not in ln.allowed}
    pph = 300.0 if g.sidewalks else 0.0
    demand = write_demand(
        net, tmp / "demand.rou.xml",
        DemandConfig(vehicles_per_hour=900, persons_per_hour=pph, end=seconds, seed=1),
    )  # fmt: skip
    vehicles, persons, pairs = set(), set(), set()
    config = SimConfig(net=net, routes=[demand], step_length=0.1, end_time=seconds)
    with Simulation(config) as sim:
        for state in sim.run():
            walking = state.is_pedestrian
            vehicles.update(state.ids[~walking].tolist())
            persons.update(state.ids[walking].tolist())
            r.closed_lane_steps += sum(1 for ln in state.lane[~walking] if ln in closed)
            pairs.update((c.a, c.b) for c in sim.collisions)
    r.collisions = len(pairs)
    r.vehicles, r.persons = len(vehicles), len(persons)
    r.traffic = r.vehicles > 0


def run_map(xodr: Path, seconds: float) -> MapResult:
    """Import, generate demand and run one map (in a worker process)."""
    r = MapResult(xodr.name)
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        tmp = Path(tmp)
        r.baseline_imported = _baseline(xodr, tmp)
        try:
            net = import_opendrive(xodr, tmp / "map.net.xml", warn=r.warnings.append)
            r.imported = True
            _traffic(net, tmp, seconds, r)
        except HiyariError as exc:
            r.error = str(exc)
        except Exception as exc:  # noqa: BLE001 - the benchmark reports every failure
            r.error = f"{type(exc).__name__}: {exc}"
    return r


def _line(r: MapResult) -> str:
    if not r.imported:
        return f"{r.name:48s} IMPORT FAILED  {r.error}"
    repairs = sum(1 for w in r.warnings if "junction shapes" not in w)
    shapes = "computed shapes" if any("junction shapes" in w for w in r.warnings) else ""
    notes = ", ".join(x for x in (f"{repairs} repairs" if repairs else "", shapes) if x)
    head = f"{r.name:48s} imported{' (' + notes + ')' if notes else ''}"
    if not r.traffic:
        return f"{head}; TRAFFIC FAILED  {r.error or 'no vehicle entered'}"
    return (f"{head}; {r.vehicles} vehicles, {r.persons} persons, {r.collisions} collision "
            f"pairs, {r.closed_lane_steps} vehicle-steps on closed lanes")  # fmt: skip


def _plot(results: list[MapResult], png: Path) -> None:
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    fig = Figure(figsize=(8, 0.28 * len(results) + 1.8))
    ax = fig.add_subplot()
    names = [r.name.removesuffix(".xodr") for r in results]
    columns = ["plain netconvert\nimport (baseline)", "hiyari\nimport", "60 s of\ntraffic"]
    for k, r in enumerate(results):
        for c, ok in enumerate((r.baseline_imported, r.imported, r.traffic)):
            ax.add_patch(Rectangle((c, k), 0.95, 0.9, color="#27ae60" if ok else "#c0392b"))
    ax.set_xlim(0, 3)
    ax.set_ylim(len(results), 0)
    ax.set_xticks([0.475, 1.475, 2.475], columns)
    ax.xaxis.tick_top()
    ax.set_yticks([k + 0.45 for k in range(len(results))], names)
    ax.set_title("Third-party OpenDRIVE maps\n(green: done, red: failed)", pad=40)
    fig.tight_layout()
    fig.savefig(png, dpi=100)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("folder", type=Path, help="folder of .xodr files")
    p.add_argument("--seconds", type=float, default=60.0, help="simulated seconds per map")
    p.add_argument("--png", type=Path, help="write a bar chart of the outcomes here")
    args = p.parse_args()
    maps = sorted(args.folder.glob("*.xodr"))
    if not maps:
        raise SystemExit(f"{args.folder}: no .xodr files")
    results = []
    ctx = multiprocessing.get_context("spawn")
    with cf.ProcessPoolExecutor(max_workers=1, mp_context=ctx, max_tasks_per_child=1) as pool:
        futures = {pool.submit(run_map, m, args.seconds): m for m in maps}
        for fut in tqdm(cf.as_completed(futures), total=len(maps), desc="maps"):
            try:
                results.append(fut.result())
            except Exception as exc:  # noqa: BLE001 - a crashed worker is a failed map
                results.append(MapResult(futures[fut].name, error=f"worker died: {exc}"))
    results.sort(key=lambda r: r.name)
    for r in results:
        print(_line(r))
        for w in r.warnings:
            print(f"    warning: {w}")
    n = len(results)
    pct = lambda k: 100.0 * k / n  # noqa: E731
    imported = sum(r.imported for r in results)
    traffic = sum(r.traffic for r in results)
    base = sum(r.baseline_imported for r in results)
    print(f"\n{n} maps: import {pct(imported):.1f} % ({imported}), 60 s of traffic "
          f"{pct(traffic):.1f} % ({traffic}); baseline plain netconvert import "
          f"{pct(base):.1f} % ({base}); ratio {imported / max(base, 1):.2f}")  # fmt: skip
    print(f"collision pairs {sum(r.collisions for r in results)}, vehicle-steps on lanes closed "
          f"to ordinary traffic {sum(r.closed_lane_steps for r in results)}")  # fmt: skip
    if args.png:
        _plot(results, args.png)
        print(f"chart: {args.png}")


if __name__ == "__main__":
    main()
