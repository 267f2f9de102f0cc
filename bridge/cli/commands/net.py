"""``hiyari net``: build road networks, import OpenDRIVE and OpenStreetMap maps, triangulate
the 3D road scene.

hiyari net build {expressway,city,intersection,r157} -o NET [--param value ...]
hiyari net import MAP.xodr -o MAP.net.xml [--all-lanes] [--junction-shapes auto|file|computed]
hiyari net import MAP.osm|MAP.osm.pbf -o MAP.net.xml [--bbox W,S,E,N] [--no-buildings]
hiyari net mesh NET -o scene.glb [-o scene.npz ...] [--buildings]
  (the mapped buildings of NET's polygon file, MAP.poly.xml beside MAP.net.xml, are always in)
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time
from collections import Counter
from functools import partial
from pathlib import Path

from hiyari.bridge.cli import numbers
from hiyari.bridge.cli.outputs import output_file
from hiyari.errors import HiyariError
from hiyari.net.sumo.build import (
    CatalogueRoadParams,
    CityGridParams,
    ExpresswayParams,
    IntersectionParams,
    R157RoadParams,
    build_catalogue_road,
    build_city_grid,
    build_expressway,
    build_intersection,
    build_r157_road,
    param_docs,
)

GENERATORS = {
    "expressway": (ExpresswayParams, build_expressway),
    "city": (CityGridParams, build_city_grid),
    "intersection": (IntersectionParams, build_intersection),
    "r157": (R157RoadParams, build_r157_road),
    # JAMA catalogue roads: OpenDRIVE (.xodr beside the net) imported with netconvert
    "mainline": (CatalogueRoadParams, partial(build_catalogue_road, geometry="main")),
    "merge": (CatalogueRoadParams, partial(build_catalogue_road, geometry="merge")),
    "branch": (CatalogueRoadParams, partial(build_catalogue_road, geometry="branch")),
    "jama-intersection": (
        CatalogueRoadParams,
        partial(build_catalogue_road, geometry="intersection"),
    ),
}


def _summary(net: Path) -> str:
    # the work of each subcommand is imported where it runs: `hiyari --help` stays fast
    from hiyari.net.road.geometry import RoadGeometry

    g = RoadGeometry.from_net(net)
    kinds = Counter(ln.kind.value for ln in g.lanes.values() if not ln.internal)
    normal = sum(1 for e in g.edges.values() if e.function == "")
    return f"{normal} edges, " + ", ".join(f"{n} {k} lanes" for k, n in sorted(kinds.items()))


def _run_build(args: argparse.Namespace) -> None:
    cls, builder = GENERATORS[args.kind]
    values = {f.name: getattr(args, f.name) for f in dataclasses.fields(cls)}
    net = builder(args.out, cls(**values))
    print(f"network: {net} ({_summary(net)})")


JUNCTION_SHAPES = {"auto": None, "file": True, "computed": False}


def _warn(message: str) -> None:
    print(f"hiyari: warning: {message}", file=sys.stderr)


def is_osm(path: str) -> bool:
    """Whether ``path`` names an OpenStreetMap extract (.osm, .osm.xml, .osm.pbf, .pbf)."""
    name = path.lower()
    return name.endswith((".osm", ".osm.xml", ".pbf"))


def parse_bbox(text: str) -> tuple[float, float, float, float]:
    """``'W,S,E,N'`` in degrees -> a tuple; ArgumentTypeError otherwise."""
    parts = text.split(",")
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != 4 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(
            f"expected west,south,east,north in degrees (four numbers), got {text!r}"
        )
    return values  # type: ignore[return-value]


def _run_import(args: argparse.Namespace) -> None:
    if is_osm(args.map):
        from hiyari.net.sumo.osm import OsmImportOptions, import_osm

        net = import_osm(
            args.map, args.out, OsmImportOptions(bbox=args.bbox, buildings=args.buildings), _warn
        )
        print(f"network: {net} ({_summary(net)})")
        if args.buildings:
            from hiyari.net.road.buildings import poly_path, read_buildings

            poly = poly_path(net)
            print(f"buildings: {poly} ({len(read_buildings(poly))} buildings)")
        return
    if args.bbox is not None:
        raise HiyariError(f"{args.map}: --bbox applies to OpenStreetMap extracts (.osm, .osm.pbf)")
    from hiyari.net.sumo.opendrive import ImportOptions, import_opendrive

    opts = ImportOptions(
        all_lanes=args.all_lanes,
        curve_resolution=args.curve_resolution,
        internal_shapes=JUNCTION_SHAPES[args.junction_shapes],
    )
    net = import_opendrive(args.map, args.out, opts, warn=_warn)
    print(f"network: {net} ({_summary(net)})")


def _run_mesh(args: argparse.Namespace) -> None:
    from hiyari.net.mesh.export import SUFFIXES, export_mesh
    from hiyari.net.mesh.materials import Material
    from hiyari.net.mesh.road_mesh import MeshParams, network_scene_mesh
    from hiyari.net.road.network import RoadNetwork
    from hiyari.net.sumo.files import check_net
    from hiyari.sumo_tools import check_net_loads

    for out in args.out:
        if Path(out).suffix.lower() not in SUFFIXES:
            raise HiyariError(f"{out}: unknown mesh format (use {', '.join(SUFFIXES)})")
    t0 = time.perf_counter()
    check_net(args.net)
    check_net_loads(args.net)  # nothing is built from a net SUMO itself rejects
    mesh = network_scene_mesh(
        RoadNetwork(args.net),
        buildings=args.buildings,
        params=MeshParams(ground=args.ground, seed=args.seed),
    )
    dt = time.perf_counter() - t0
    counts = Counter(Material(int(m)).name.lower() for m in mesh.material)
    detail = ", ".join(f"{k} {n}" for k, n in sorted(counts.items()))
    print(
        f"mesh: {len(mesh.vertices)} vertices, {len(mesh.faces)} triangles ({detail}) in {dt:.2f} s"
    )
    for out in args.out:
        print(f"scene: {export_mesh(mesh, out)}")


def run(args: argparse.Namespace) -> int:
    for out in args.out if isinstance(args.out, list) else [args.out]:
        output_file(out, "-o")
    {"build": _run_build, "import": _run_import, "mesh": _run_mesh}[args.net_command](args)
    return 0


def _add_params(parser: argparse.ArgumentParser, cls: type) -> None:
    docs = param_docs(cls)
    for f in dataclasses.fields(cls):
        flag = "--" + f.name.replace("_", "-")
        # argparse expands %-formats in help texts: a literal % (a grade in %) is doubled
        text = f"{docs[f.name]} (default: {f.default})".replace("%", "%%")
        if isinstance(f.default, bool):
            parser.add_argument(
                flag, action=argparse.BooleanOptionalAction, default=f.default, help=text
            )
        else:
            parser.add_argument(flag, type=type(f.default), default=f.default, help=text)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "net", help="road networks: build, import OpenDRIVE / OpenStreetMap, 3D scene mesh"
    )
    p.set_defaults(func=run)
    nsub = p.add_subparsers(dest="net_command", required=True, metavar="NET_COMMAND")

    b = nsub.add_parser("build", help="generate a SUMO network (plain XML + netconvert)")
    bsub = b.add_subparsers(dest="kind", required=True, metavar="KIND")
    for kind, (cls, _) in GENERATORS.items():
        kp = bsub.add_parser(kind, help=(cls.__doc__ or "").splitlines()[0])
        kp.add_argument("-o", "--out", required=True, help="output .net.xml")
        _add_params(kp, cls)

    i = nsub.add_parser(
        "import", help="convert an OpenDRIVE (.xodr) or OpenStreetMap (.osm, .osm.pbf) map"
    )
    i.add_argument("map", help="OpenDRIVE file, or OpenStreetMap extract (.osm, .osm.pbf)")
    i.add_argument("-o", "--out", required=True, help="output .net.xml")
    i.add_argument(
        "--bbox",
        type=parse_bbox,
        default=None,
        help="OSM: cut the area west,south,east,north (degrees) out of the extract",
    )
    i.add_argument(
        "--buildings",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="OSM: write the buildings beside the net (MAP.poly.xml) for the 3D scene",
    )
    i.add_argument(
        "--all-lanes",
        action="store_true",
        help="OpenDRIVE: also import the verge lane types (border, curb, median ...), closed "
        "to traffic",
    )
    i.add_argument(
        "--junction-shapes",
        choices=list(JUNCTION_SHAPES),
        default="auto",
        help="OpenDRIVE: lanes inside junctions: the file's connecting roads (file), netconvert's computed "
        "shapes (computed), or the file's unless they disagree with SUMO's junction logic (auto)",
    )
    i.add_argument(
        "--curve-resolution", type=float, default=2.0, help="OpenDRIVE: point spacing on curves, m"
    )

    m = nsub.add_parser("mesh", help="triangulate a SUMO net into the 3D road scene")
    m.add_argument("net", help="SUMO .net.xml")
    m.add_argument(
        "-o",
        "--out",
        action="append",
        required=True,
        help="output file, repeatable: .glb / .gltf / .ply (viewers) or .npz (arrays)",
    )
    m.add_argument(
        "--buildings",
        action="store_true",
        help="simple generated buildings on enclosed blocks (nets without mapped buildings)",
    )
    m.add_argument(
        "--ground", action=argparse.BooleanOptionalAction, default=True, help="grass ground plane"
    )
    m.add_argument("--seed", type=numbers.seed(), default=0, help="seed of the building heights")
