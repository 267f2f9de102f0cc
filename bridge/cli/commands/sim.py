"""``hiyari sim``: run a SUMO config, or a net with routes or generated demand, headless."""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from pathlib import Path

from hiyari.atomic import write_text_atomic
from hiyari.bridge.cli import numbers
from hiyari.bridge.cli.outputs import output_file
from hiyari.errors import HiyariError, about


def parse_mix(text: str) -> dict[str, float]:
    """'car=0.8,truck=0.2' -> {'car': 0.8, 'truck': 0.2}."""
    mix = {}
    for part in filter(None, text.split(",")):
        name, _, share = part.partition("=")
        try:
            value = float(share) if share else 1.0
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value >= 0):
            raise HiyariError(f"--mix: share of {name!r} must be a number >= 0, got {share!r}")
        mix[name.strip()] = value
    return mix


def run(args: argparse.Namespace) -> int:
    # SUMO is imported here, not at the top, so that the other commands do not load it
    from hiyari.net.sumo.files import check_net
    from hiyari.traffic.demand import DemandConfig, write_demand
    from hiyari.traffic.simulation import SimConfig
    from hiyari.traffic.traffic_run import run_traffic

    # the summary is written at the end: refused before any work, into an existing folder
    json_out = None if args.json is None else output_file(args.json, "--json", False)
    routes = [Path(r) for r in args.routes]
    generated: list[Path] = []
    if args.net:
        check_net(args.net)  # a broken net is named as such before demand is made from it
    with tempfile.TemporaryDirectory(prefix="hiyari-sim-") as tmp:
        if args.net and (args.vph or args.pph):
            demand = DemandConfig(
                vehicles_per_hour=args.vph,
                persons_per_hour=args.pph,
                end=args.duration,
                seed=args.seed,
                vehicle_mix=parse_mix(args.mix),
            )
            with about(args.net):
                generated.append(write_demand(args.net, Path(tmp) / "demand.rou.xml", demand))
        if args.config:  # the user's scenario over its own time window, its files checked
            config = SimConfig.from_sumocfg(
                args.config, args.step, args.seed, routes=routes, preflight=True
            )
        else:
            config = SimConfig(
                net=Path(args.net),
                routes=[*routes, *generated],
                step_length=args.step,
                seed=args.seed,
                generated=generated,
                preflight=True,
            )
        summary = run_traffic(config, args.duration, progress=not args.quiet)
    d = summary.as_dict()
    print(
        f"simulated {d['sim_seconds']:.0f} s in {d['wall_seconds']:.2f} s wall "
        f"({d['steps_per_second']:.0f} steps/s, {d['realtime_factor']:.0f}x real time); "
        f"vehicles {d['vehicles_seen']} (max {d['max_vehicles']} at once), "
        f"persons {d['persons_seen']} (max {d['max_persons']}), "
        f"collision pairs {len(d['collision_pairs'])}"
    )
    if json_out is not None:
        write_text_atomic(json_out, json.dumps(d, indent=2))
        print(f"summary: {json_out}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sim", help="run SUMO headless for a duration and print counts")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--config", "-c", help="SUMO .sumocfg file")
    src.add_argument("--net", "-n", help="SUMO .net.xml file")
    p.add_argument("--routes", "-r", nargs="*", default=[], help="route / demand files")
    p.add_argument(
        "--vph", type=numbers.per_hour(), default=0.0, help="generated vehicles per hour"
    )
    p.add_argument("--pph", type=numbers.per_hour(), default=0.0, help="generated persons per hour")
    p.add_argument("--mix", default="car=1", help="vehicle mix, e.g. car=0.8,truck=0.1,bus=0.1")
    p.add_argument(
        "--duration", "-d", type=numbers.seconds(), default=300.0, help="simulated duration, s"
    )
    p.add_argument(
        "--step",
        type=numbers.number(0.0, 60.0, lo_open=True, unit="s", what="the step length"),
        default=0.1,
        help="step length, s",
    )
    p.add_argument("--seed", type=numbers.seed(), default=42)
    p.add_argument("--json", help="write the summary as JSON here")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    p.set_defaults(func=run)
