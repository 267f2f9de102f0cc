"""Runs/s of a 200-run closed-loop sweep: 1 and 2 local workers and a local Ray cluster.

The grid is a UN R157 cut-in (perfect perception, 20 s per run): 10 Vo0 x 20 dx0 values.
Each backend runs the whole grid from an empty folder; the result tables must be identical.

Run: .venv/bin/python benchmarks/sweep.py
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from hiyari.bridge.openscenario.presets.toml_file import load_scenario
from hiyari.bridge.studies.sweep import SweepOptions, run_sweep

GRID = """
[scenario]
type = "cut-in"
name = "benchmark cut-in grid"
seed = 1
duration = 20.0
[ego]
perception = "perfect"
[parameters]
ve0_kmh = 60
vo0_kmh = { range = [5, 50], step = 5 }
dx0_m = { range = [2, 40], step = 2 }
vy_ms = 1.0
"""


def main() -> None:
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp:
        scen = Path(tmp) / "grid.toml"
        scen.write_text(GRID)
        logical = load_scenario(scen)
        n = len(logical.expand())
        results = {}
        tables = {}
        for name, opts in (
            ("local, 1 worker", dict(workers=1)),
            ("local, 2 workers", dict(workers=2)),
            ("ray (local cluster), 2 CPUs", dict(workers=2, backend="ray")),
        ):
            s = run_sweep(
                logical, SweepOptions(Path(tmp) / name.split(",")[0] / name, progress=False, **opts)
            )
            results[name] = s.wall_seconds
            tables[name] = s.table.read_bytes()
    base = results["local, 1 worker"]
    print(f"{n}-run closed-loop cut-in grid (perfect perception, 20 s simulated per run)")
    print(f"{'backend':30s} {'wall s':>8s} {'runs/s':>8s} {'speed-up vs 1 worker':>21s}")
    for name, wall in results.items():
        print(f"{name:30s} {wall:8.1f} {n / wall:8.2f} {base / wall:20.2f}x")
    overhead = (results["ray (local cluster), 2 CPUs"] - results["local, 2 workers"]) / n * 2
    print(f"Ray overhead per run vs the local pool (2 workers): {overhead * 1000:+.0f} ms")
    print("identical result tables:", len(set(tables.values())) == 1)


if __name__ == "__main__":
    main()
