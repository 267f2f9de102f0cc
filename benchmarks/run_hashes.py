"""Hashes of the outputs of a fixed set of runs, to show that a refactoring changes no result.

Runs through the CLI, into ``--work`` (use the same folder before and after: some outputs name
their paths):

- the 15 ALKS OpenSCENARIO files (``hiyari run``, perfect perception, ``--max-duration``);
- the TOML presets of ``bridge/openscenario/presets/library`` (``hiyari run``);
- a 2-run-per-cell catalogue subset (``hiyari evaluate --cells M02,M03``);
- a TOML and an .xosc sweep (``hiyari sweep``) and an R157 judge sample (``hiyari r157``).

Hashed: result.json without its wall-clock field, results.csv (the catalogue's without
``wall_s``), timeseries.csv, judge.csv, and every recording's message payloads, channels and
metadata (without the creation time). One line per file, ``sha256  relative/path``, written
to ``--save`` and compared with ``--compare`` (exit 1 on a difference)::

    python benchmarks/run_hashes.py --work /tmp/hashes --save before.txt
    python benchmarks/run_hashes.py --work /tmp/hashes --save after.txt --compare before.txt
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

from mcap.reader import make_reader

from hiyari.checkout import shared_dir

REPO = Path(__file__).resolve().parents[1]
SHARED = shared_dir()
ALKS = SHARED / "data" / "openscenario" / "alks"
PRESETS = REPO / "bridge" / "openscenario" / "presets" / "library"
#: Fields that hold wall-clock time (not results).
WALL = {"wall_seconds", "wall_s", "creation_time"}


#: Exit status and last error line of each command that failed (a result to compare too).
FAILURES: dict[str, str] = {}


def hiyari(*args: str) -> float:
    """Run ``hiyari args``; wall seconds. Exit status 0 or 3 (a collision) is a result; any
    other is kept in FAILURES with the error's last line (compared like the outputs)."""
    t0 = time.perf_counter()
    cmd = [sys.executable, "-m", "hiyari", *args]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode not in (0, 3):
        last = (done.stderr.strip().splitlines() or [""])[-1]
        FAILURES[" ".join(a.replace(str(REPO), ".") for a in args[:2])] = (
            f"exit {done.returncode}: {last}"
        )
    return time.perf_counter() - t0


def _drop_wall(doc: object) -> object:
    if isinstance(doc, dict):
        return {k: _drop_wall(v) for k, v in doc.items() if k not in WALL}
    if isinstance(doc, list):
        return [_drop_wall(v) for v in doc]
    return doc


def _csv_without_wall(path: Path) -> bytes:
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    keep = [i for i, name in enumerate(rows[0]) if name not in WALL]
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows([[r[i] for i in keep] for r in rows])
    return buf.getvalue().encode()


def _recording(path: Path) -> bytes:
    """Schemas, channels, metadata (without the creation time) and messages, in file order."""
    h = hashlib.sha256()
    with path.open("rb") as f:
        reader = make_reader(f)
        for meta in reader.iter_metadata():
            h.update(json.dumps([meta.name, _drop_wall(meta.metadata)], sort_keys=True).encode())
        for schema, channel, msg in reader.iter_messages(log_time_order=False):
            head = [schema.name if schema else "", channel.topic, msg.log_time, msg.publish_time]
            h.update(json.dumps(head).encode())
            h.update(msg.data)
    return h.digest()


def digest(path: Path) -> str:
    """The hash of one output file, wall-clock fields left out."""
    if path.name == "result.json":
        data = json.dumps(_drop_wall(json.loads(path.read_text())), sort_keys=True).encode()
    elif path.suffix == ".csv" and path.name != "timings.csv":
        data = _csv_without_wall(path)
    elif path.suffix == ".mcap":
        data = _recording(path)
    else:
        data = path.read_bytes()
    return hashlib.sha256(data).hexdigest()


HASHED = ("result.json", "results.csv", "timeseries.csv", "judge.csv", "*.mcap")


def run_all(work: Path, parts: set[str], max_duration: float) -> dict[str, float]:
    """Every run of the set (see module); wall seconds per part."""
    walls: dict[str, float] = {}
    if "alks" in parts:
        for xosc in sorted(ALKS.glob("*.xosc")):
            out = work / "alks" / xosc.stem.removesuffix("_template")
            walls[f"alks/{out.name}"] = hiyari(
                "run", str(xosc), "-o", str(out), "--perception", "perfect", "-q",
                "--max-duration", str(max_duration),
            )  # fmt: skip
    if "toml" in parts:
        for toml in sorted(PRESETS.glob("*.toml")):
            out = work / "toml" / toml.stem
            walls[f"toml/{toml.stem}"] = hiyari("run", str(toml), "-o", str(out), "-q")
    if "catalogue" in parts:
        out = work / "catalogue"
        walls["catalogue"] = hiyari(
            "evaluate", "--cells", "M02,M03", "--runs-per-cell", "2", "-o", str(out), "-q",
            "-j", "2",
        )  # fmt: skip
    if "sweep" in parts:
        walls["sweep/toml"] = hiyari(
            "sweep", str(PRESETS / "cut_in_grid.toml"), "-o", str(work / "sweep" / "toml"),
            "-q", "-j", "2",
        )  # fmt: skip
        dist = REPO / "examples" / "openscenario"
        walls["sweep/xosc"] = hiyari(
            "sweep", str(next(iter(sorted(dist.glob("*distribution*.xosc"))))),
            "-o", str(work / "sweep" / "xosc"), "-q", "-j", "2",
        )  # fmt: skip
    if "judge" in parts:
        points = work / "judge" / "points" / "r157_points.csv"
        hiyari("r157", "points", "--ve", "40:60:20", "-o", str(points.parent))
        walls["judge"] = hiyari(
            "r157", "judge", str(points), "--sample", "12", "-o", str(work / "judge"), "-q",
            "-j", "2",
        )  # fmt: skip
    return walls


def hashes(work: Path) -> dict[str, str]:
    """``relative path -> hash`` of every hashed output under ``work``."""
    found = sorted({p for pattern in HASHED for p in work.rglob(pattern)})
    return {str(p.relative_to(work)): digest(p) for p in found}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, required=True, help="output folder (emptied first)")
    ap.add_argument("--save", type=Path, required=True, help="write the hashes here")
    ap.add_argument("--compare", type=Path, default=None, help="hashes to compare with")
    ap.add_argument("--parts", default="alks,toml,catalogue,sweep,judge")
    ap.add_argument("--max-duration", type=float, default=60.0, help="ALKS runs, s")
    ap.add_argument("--no-run", action="store_true", help="hash what is in --work")
    args = ap.parse_args(argv)
    if not args.no_run:
        shutil.rmtree(args.work, ignore_errors=True)
        walls = run_all(args.work, set(args.parts.split(",")), args.max_duration)
        for name, wall in walls.items():
            print(f"{wall:8.1f} s  {name}")
    found = hashes(args.work)
    found.update({f"failed: {cmd}": why.replace("  ", " ") for cmd, why in FAILURES.items()})
    args.save.write_text("".join(f"{h}  {p}\n" for p, h in found.items()))
    print(f"{len(found)} files hashed -> {args.save}")
    if args.compare is None:
        return 0
    before = dict(reversed(line.split("  ", 1)) for line in args.compare.read_text().splitlines())
    differ = sorted(p for p in before.keys() | found.keys() if before.get(p) != found.get(p))
    for p in differ:
        print(f"DIFFERS: {p} ({before.get(p, 'missing')[:12]} -> {found.get(p, 'missing')[:12]})")
    print(f"{len(found) - len(differ)} identical, {len(differ)} differ")
    return 1 if differ else 0


if __name__ == "__main__":
    raise SystemExit(main())
