"""Sweeps of the SCT incident study: share of SCT vehicles and pedestrian volume.

Runs the study's arms over a grid of penetration rates (0..100 % SCT vehicles) and pedestrian
volumes, each point with the same seeds, and writes ``sweep.csv`` and ``sweep.png`` (incidents
and mean travel time against penetration, one line per pedestrian volume) to the output folder.
Each point is a short study (default 6 simulated hours of the unsignalised intersection); all
points run in parallel processes.

Run: .venv/bin/python examples/sct_sweeps.py -o out/sct_sweeps [--hours 6]
"""

from __future__ import annotations

import argparse
import csv
from dataclasses import replace
from pathlib import Path

from matplotlib.figure import Figure
from tqdm import tqdm  # noqa: E402

from hiyari.atomic import atomic_path  # noqa: E402
from hiyari.bridge.studies.sct.study import StudyConfig, build_inputs, run_tasks  # noqa: E402
from hiyari.bridge.studies.sct.summary import summarise  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--out", default="out/sct_sweeps", help="output folder")
    ap.add_argument("--hours", type=float, default=6.0, help="simulated hours per point")
    ap.add_argument("--penetration", default="0,0.25,0.5,0.75,1", help="SCT shares")
    ap.add_argument("--pph", default="150,300,600", help="pedestrians per hour")
    ap.add_argument("--jobs", type=int, help="parallel processes (default: CPU count)")
    args = ap.parse_args()
    out = Path(args.out)
    shares = [float(x) for x in args.penetration.split(",")]
    volumes = [float(x) for x in args.pph.split(",")]
    rows = []
    points = [(p, v) for v in volumes for p in shares]
    tasks, keys = [], []
    for pph in volumes:
        base = StudyConfig(days=args.hours / 24.0, runs=1, persons_per_hour=pph)
        inputs = build_inputs(base, out / f"inputs_pph{pph:g}")
        for share in shares:
            cfg = replace(base, penetration=share)
            # 0 % SCT is the baseline arm; every other point needs only its SCT arm
            arm = "baseline" if share == 0 else "sct"
            tasks += [replace(t, study=cfg) for t in inputs if t.arm == arm]
            keys.append((share, pph, cfg))
    total = sum(t.study.run_seconds for t in tasks)
    with tqdm(total=round(total), unit="sim s", desc="sweep") as bar:
        results = run_tasks(tasks, args.jobs, lambda s: bar.update(round(s)))
    for (share, pph, cfg), r in zip(keys, results, strict=True):
        s = [x for x in summarise(cfg, [r]) if x.arm == r.arm][0]
        rows.append(
            {
                "penetration": share,
                "persons_per_hour": pph,
                "hours": args.hours,
                "incidents": s.incidents,
                "collisions": s.collisions,
                "vehicles": s.vehicles,
                "mean_travel_time_s": round(s.mean_travel_time, 2),
                "mean_delay_s": round(s.mean_time_loss, 2),
            }
        )
    out.mkdir(parents=True, exist_ok=True)
    with atomic_path(out / "sweep.csv") as tmp, tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    fig = Figure(figsize=(11, 4))
    ax1, ax2 = fig.subplots(1, 2)
    for pph in volumes:
        pts = sorted(
            (r for r in rows if r["persons_per_hour"] == pph), key=lambda r: r["penetration"]
        )
        x = [100 * r["penetration"] for r in pts]
        ax1.plot(x, [r["incidents"] for r in pts], "o-", label=f"{pph:g} ped/h")
        ax2.plot(x, [r["mean_travel_time_s"] for r in pts], "o-", label=f"{pph:g} ped/h")
    ax1.set_xlabel("SCT vehicles, %")
    ax1.set_ylabel(f"incidents in {args.hours:g} h")
    ax2.set_xlabel("SCT vehicles, %")
    ax2.set_ylabel("mean travel time, s")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend()
    with atomic_path(out / "sweep.png") as tmp:
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    print(f"{len(points)} points ({len(volumes)} volumes x {len(shares)} shares)")
    for r in rows:
        print(
            f"  {100 * r['penetration']:5.0f} % SCT, {r['persons_per_hour']:5.0f} ped/h: "
            f"{r['incidents']:4d} incidents, travel time {r['mean_travel_time_s']:.1f} s"
        )
    print(f"outputs in {out.resolve()}: sweep.csv, sweep.png, inputs_*/")


if __name__ == "__main__":
    main()
