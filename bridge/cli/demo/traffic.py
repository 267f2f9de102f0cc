"""Demo stage: a generated city intersection with vehicles and pedestrians; every contact in
collisions.csv with the actors, where and why (traffic.contact_context)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

from matplotlib.figure import Figure

from hiyari.atomic import atomic_path  # noqa: E402
from hiyari.net.sumo.build import IntersectionParams, build_intersection  # noqa: E402
from hiyari.traffic.contact_context import reason_counts
from hiyari.traffic.demand import DemandConfig, write_demand  # noqa: E402
from hiyari.traffic.simulation import SimConfig  # noqa: E402
from hiyari.traffic.traffic_run import TrafficSummary, run_traffic  # noqa: E402
from hiyari.units import mps_to_kmh


def plot_traffic(summary: TrafficSummary, out: Path) -> Path:
    """PNG of actors in the network and mean vehicle speed over time."""
    fig = Figure(figsize=(8, 5.5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.plot(summary.times, summary.vehicle_counts, label="vehicles")
    ax1.plot(summary.times, summary.person_counts, label="pedestrians")
    ax1.set_ylabel("actors in network")
    ax1.legend(loc="upper left")
    ax1.grid(alpha=0.3)
    ax2.plot(summary.times, mps_to_kmh(summary.mean_vehicle_speed), color="tab:green")
    ax2.set_ylabel("mean vehicle speed (km/h)")
    ax2.set_xlabel("simulation time (s)")
    ax2.grid(alpha=0.3)
    fig.suptitle("hiyari demo: signalised four-leg intersection")
    fig.tight_layout()
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return out


def run_traffic_demo(out_dir: Path, duration: float = 300.0, seed: int = 42) -> dict:
    """Build the intersection, generate demand, run it; write summary, CSV and PNG."""
    out_dir.mkdir(parents=True, exist_ok=True)
    net = build_intersection(
        out_dir / "intersection.net.xml", IntersectionParams(traffic_light=True)
    )
    routes = write_demand(
        net,
        out_dir / "demand.rou.xml",
        DemandConfig(
            vehicles_per_hour=900,
            persons_per_hour=900,
            end=duration,
            seed=seed,
            vehicle_mix={"car": 0.8, "truck": 0.05, "bus": 0.05, "motorcycle": 0.1},
        ),
    )
    summary = run_traffic(SimConfig(net=net, routes=[routes], seed=seed), duration)
    d = summary.as_dict()
    with atomic_path(out_dir / "traffic_summary.json") as tmp:
        tmp.write_text(json.dumps(d, indent=2))
    with atomic_path(out_dir / "collisions.csv") as tmp, tmp.open("w", newline="") as f:
        w = csv.writer(f)
        cols = ["time", "a", "b", "kind", "depth_m", "reported_by_sumo", "a_class", "b_class",
                "a_lane", "b_lane", "a_speed", "b_speed", "where", "reason", "why"]  # fmt: skip
        w.writerow(["time_s", *cols[1:10], "a_speed_mps", "b_speed_mps", *cols[12:]])
        for c in d["collision_pairs"]:
            w.writerow([c.get(k, "") for k in cols])
    plot_traffic(summary, out_dir / "traffic.png")
    d["contact_reasons"] = reason_counts(list(summary.contexts.values()))
    return d
