"""Scene-mesh build time against a plain netconvert run of the same network, in one run.

Networks: a 2 km x 2 km city grid (10 x 10 blocks of 200 m, sidewalks, crossings, traffic
lights) and every ALKS OpenDRIVE road in ../shared/data/opendrive/alks (largest file first;
the most triangles come from the 1.5 km arc of radius 1000 m, sampled every 2 m). For each,
the baseline is netconvert writing the .net.xml from the same input (plain XML, or the
.xodr); the measured figure is reading that net into a RoadGeometry plus triangulating the
scene (with buildings for the city). Times are the best of ``--repeat`` runs.

Run: .venv/bin/python benchmarks/mesh.py
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from hiyari.checkout import shared_dir
from hiyari.net.mesh.road_mesh import build_scene_mesh
from hiyari.net.road.geometry import RoadGeometry
from hiyari.net.sumo.build import CityGridParams, city_grid_plain
from hiyari.net.sumo.opendrive import import_opendrive
from hiyari.net.sumo.plain_xml import write_plain
from hiyari.sumo_tools import run_sumo_tool

CITY = CityGridParams(blocks_x=10, blocks_y=10, block_length=200.0)
ALKS = shared_dir() / "data" / "opendrive" / "alks"


def best(fn: Callable[[], object], repeat: int) -> tuple[float, object]:
    """Smallest wall time of ``repeat`` calls of ``fn`` and the last result."""
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return min(times), result


def city_netconvert_args(tmp: Path) -> list[str]:
    """netconvert arguments that build the benchmark city from its plain XML."""
    nodes, edges, options = city_grid_plain(CITY)
    inputs = write_plain(tmp, nodes, edges)
    return [*inputs, "-o", str(tmp / "city.net.xml"), *options]


def measure(
    name: str, netconvert_args: list[str], net: Path, buildings: bool, repeat: int
) -> tuple[str, int, int, float, float, float]:
    t_nc, _ = best(lambda: run_sumo_tool("netconvert", netconvert_args, name), repeat)

    def mesh():
        g = RoadGeometry.from_net(net)
        return g, build_scene_mesh(g, buildings=buildings)

    t_mesh, (g, m) = best(mesh, repeat)
    t_geom, _ = best(lambda: RoadGeometry.from_net(net), repeat)
    lanes = sum(1 for ln in g.lanes.values() if not ln.internal)
    return name, lanes, len(m.faces), t_nc, t_geom, t_mesh


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="runs per measurement (best kept)")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory(prefix="hiyari-bench-") as tmp_name:
        tmp = Path(tmp_name)
        nc_args = city_netconvert_args(tmp)
        run_sumo_tool("netconvert", nc_args, "city")
        rows.append(
            measure(
                "city 2 km x 2 km (+buildings)", nc_args, tmp / "city.net.xml", True, args.repeat
            )
        )
        for xodr in sorted(ALKS.glob("*.xodr"), key=lambda p: -p.stat().st_size):
            net = import_opendrive(xodr, tmp / f"{xodr.stem}.net.xml")
            nc_args = [
                "--opendrive-files",
                str(xodr),
                "--offset.disable-normalization",
                "true",
                "--no-turnarounds",
                "true",
                "--precision",
                "3",
                "--opendrive.internal-shapes",
                "true",
                "-o",
                str(tmp / f"{xodr.stem}.again.net.xml"),
            ]
            rows.append(measure(xodr.stem, nc_args, net, False, args.repeat))
    print(
        f"{'network':32s} {'lanes':>6s} {'triangles':>10s} {'netconvert s':>13s} "
        f"{'geometry s':>11s} {'geom+mesh s':>12s} {'mesh / netconvert':>18s}"
    )
    for name, lanes, tris, t_nc, t_geom, t_mesh in rows:
        print(
            f"{name:32s} {lanes:6d} {tris:10d} {t_nc:13.3f} {t_geom:11.3f} {t_mesh:12.3f} "
            f"{t_mesh / t_nc:17.2f}x"
        )


if __name__ == "__main__":
    main()
