"""``hiyari sensors render``: one frame of a scenario through one sensor under one preset."""

from __future__ import annotations

import argparse
from pathlib import Path

from hiyari.bridge.cli import numbers
from hiyari.bridge.cli.outputs import output_folder


def run(args: argparse.Namespace) -> int:
    from hiyari.bridge.cli.sensor_frame import FrameRequest, render_sensor_frame

    req = FrameRequest(
        sensor=args.sensor,
        preset=args.preset,
        out=output_folder(args.out),
        lidar_preset=args.lidar,
        radar_preset=args.radar,
        camera_preset=args.camera,
        net=Path(args.net) if args.net else None,
        routes=tuple(Path(r) for r in args.routes),
        vehicles_per_hour=args.vph,
        persons_per_hour=args.pph,
        time_s=args.time,
        ego=args.ego,
        seed=args.seed,
    )
    paths = render_sensor_frame(req)
    print(f"{args.sensor} frame under '{args.preset}' written:")
    for p in paths:
        print(f"   {p}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sensors", help="ray-cast sensor models (LiDAR, radar, camera)")
    ssub = p.add_subparsers(dest="sensors_command", required=True, metavar="SUBCOMMAND")
    ssub.add_parser(
        "render",
        help="one frame through one sensor under a disturbance preset: raw output, objects, PNG",
        setup=_render_arguments,  # the presets load the sensor models: only when used
    )


def _render_arguments(r: argparse.ArgumentParser) -> None:
    from hiyari.bridge.cli.sensor_frame import SENSOR_KINDS
    from hiyari.sensors.camera.config import CAMERA_PRESETS
    from hiyari.sensors.environment.presets import PRESETS
    from hiyari.sensors.lidar.config import LIDAR_PRESETS
    from hiyari.sensors.radar.config import RADAR_PRESETS

    r.description = (
        f"Disturbance presets: {', '.join(PRESETS)}. LiDAR: {', '.join(LIDAR_PRESETS)}; "
        f"radar: {', '.join(RADAR_PRESETS)}; camera: {', '.join(CAMERA_PRESETS)}."
    )
    r.add_argument("--sensor", default="lidar", help=f"one of {', '.join(SENSOR_KINDS)}")
    r.add_argument("--preset", default="clear", help="perception-disturbance preset (see above)")
    r.add_argument("--lidar", default="64ch", help="LiDAR preset")
    r.add_argument("--radar", default="narrow", help="radar preset")
    r.add_argument("--camera", default="wide", help="camera preset")
    r.add_argument("--net", help="SUMO .net.xml to run (default: the built-in street scene)")
    r.add_argument(
        "--routes", nargs="*", default=[], help="route files for --net (default: generated demand)"
    )
    r.add_argument(
        "--vph", type=numbers.per_hour(), default=1800.0, help="generated vehicles per hour (--net)"
    )
    r.add_argument(
        "--pph", type=numbers.per_hour(), default=1200.0, help="generated persons per hour (--net)"
    )
    r.add_argument(
        "--time",
        type=numbers.seconds(lo_open=False),
        default=60.0,
        help="simulation time of the frame, s (--net)",
    )
    r.add_argument("--ego", help="SUMO id of the ego vehicle (--net; default: the most central)")
    r.add_argument("--seed", type=numbers.seed(), default=1)
    r.add_argument("-o", "--out", default="out/sensors", help="output folder")
    r.set_defaults(func=run)
