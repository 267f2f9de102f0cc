"""Import an OpenStreetMap extract (.osm, .osm.pbf) into a SUMO net the way SUMO's own OSM
workflow does (``osmWebWizard.py`` / ``osmBuild.py`` with pedestrians), and its buildings
into a polygon file beside the net.

Every netconvert choice is one row of ``NETCONVERT_OPTIONS`` with the reason for it. In
short: SUMO's OSM type maps (roads; pedestrians: sidewalk widths per street type; bicycles:
cycle lanes from ``cycleway=*``); sidewalks from the ``sidewalk=*`` tags where mapped, on both
sides of every street (primary ... residential) elsewhere; crossings at the mapped ``highway=crossing`` nodes and guessed at
junctions elsewhere; traffic lights at the mapped ``highway=traffic_signals`` (a signal
mapped on the approaches of a junction regulates the junction, the signals of one junction
act as one); junction clusters joined; ramps guessed; speed limits and lane counts from
``maxspeed`` / ``lanes``, the type map's defaults elsewhere; only roads that cars, buses,
trucks, bicycles or pedestrians use (no railways) and no piece cut off from the rest.

Coordinates: netconvert's UTM projection of the extract, shifted so that the network starts
near (0, 0) (the ``<location>`` element keeps the offset and projection; SUMO and sumolib
convert back to longitude / latitude). Ids: edge ids are OSM way ids (``-`` for the reverse
direction, ``#k`` for the k-th piece of a way), junction ids OSM node ids; every edge keeps
its way ids in ``<param key="origId">`` and its street name in ``name``.

Buildings: polyconvert writes the extract's areas (SUMO's ``osmPolyconvert`` type map,
multipolygon relations assembled) into ``<net stem>.poly.xml`` beside the net, every OSM tag
kept as a ``<param>``; ``hiyari.net.road.buildings`` reads the buildings from it.

Repairs: what netconvert would stop on is repaired on a temporary copy first
(``hiyari.net.sumo.osm.repair``), one warning line per repair; the user's file is never
modified. The copy carries the heights of bridges and tunnels (``osm_levels``). After
netconvert, junctions where SUMO's logic would let vehicles collide are repaired
(``junction_repair``: joined clusters converted again unjoined, crossings narrowed, dead-start
lanes closed, collapsed lanes straightened), one warning line each, and the car conflicts
left are reported as SUMO's limit.
"""

from __future__ import annotations

import logging
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.net.road.buildings import poly_path
from hiyari.net.sumo.files import check_net
from hiyari.net.sumo.osm.junction_repair import CLOSE_PASS, clusters_to_unjoin, repair_net
from hiyari.net.sumo.osm.repair import BBox, check_bbox, repair_osm, sidewalk_types
from hiyari.sumo_tools import run_sumo_tool, sumo_home

_log = logging.getLogger(__name__)

#: SUMO's type maps (``data/typemap`` of the eclipse-sumo wheel), read in this order (a later
#: map refines the types of an earlier one).
TYPE_MAPS = ("osmNetconvert.typ.xml", "osmNetconvertPedestrians.typ.xml",
             "osmNetconvertBicycle.typ.xml")  # fmt: skip

#: Vehicle classes whose roads are imported (an edge that allows none of them is dropped).
KEPT_CLASSES = "passenger,bus,truck,delivery,motorcycle,bicycle,pedestrian"


@dataclass(frozen=True)
class NetconvertOption:
    """One netconvert option of the import and why it is set."""

    name: str
    value: str
    why: str


#: The one table of netconvert options for OpenStreetMap (the type maps and the bounding box
#: are added by ``import_osm``).
NETCONVERT_OPTIONS: tuple[NetconvertOption, ...] = tuple(
    NetconvertOption(*row)
    for row in (
        ("--osm.sidewalks", "true", "sidewalks from sidewalk=* (both, left, right, no, separate) "
         "where mapped; streets that map none get sidewalk=both in the repaired copy (the "
         "street types SUMO's pedestrian type map gives a sidewalk width)"),
        ("--osm.crossings", "true", "a crossing at every mapped highway=crossing node"),
        ("--crossings.guess", "true", "crossings at junctions whose crossings are not mapped"),
        ("--walkingareas", "true", "walking areas join sidewalks and crossings at every "
         "junction, so pedestrians get from one sidewalk to the next"),
        ("--osm.bike-access", "true", "cycle lanes from cycleway=* with the bicycle type map"),
        ("--tls.guess-signals", "true", "signals mapped on the approaches of a junction (OSM "
         "maps them at the stop line) regulate that junction"),
        ("--tls.join", "true", "the signals of one junction cluster act as one controller"),
        ("--tls.discard-simple", "true", "a lone signal node not at a junction (a pedestrian "
         "light mid-block) stays a crossing, not a controller of nothing"),
        ("--osm.elevation", "true", "bridges and tunnels at the heights of their OSM layers "
         "(ele tags the repaired copy carries, hiyari.net.sumo.osm.levels); every other road "
         "on the ground"),
        ("--junctions.join", "true", "the nodes OSM maps for one junction of dual "
         "carriageways become one junction"),
        ("--ramps.guess", "true", "acceleration and deceleration lanes at motorway ramps"),
        ("--roundabouts.guess", "true", "right of way inside roundabouts"),
        ("--no-turnarounds.except-deadend", "true", "U-turns only at dead ends: a U-turn at "
         "a junction sweeps across the crossings there, which SUMO's pedestrians do not "
         "see as a foe"),
        ("--geometry.remove", "true", "shape-only nodes joined into longer edges"),
        ("--keep-edges.by-vclass", KEPT_CLASSES, "only drivable and walkable roads (no "
         "railways, waterways, aerialways)"),
        ("--remove-edges.isolated", "true", "no piece of road cut off from the rest (an "
         "extract's edge cuts leave some): demand never starts where it cannot leave"),
        ("--output.original-names", "true", "each edge keeps its OSM way ids (param origId)"),
        ("--output.street-names", "true", "each edge keeps its street name"),
    )
)  # fmt: skip


@dataclass(frozen=True)
class OsmImportOptions:
    """How the extract is imported. ``bbox``: west, south, east, north (degrees) to cut an
    area out of the extract (roads with a node inside are kept); ``buildings``: also write
    the polygon file with the buildings beside the net."""

    bbox: BBox | None = None
    buildings: bool = True


def netconvert_args(osm: Path, bbox: BBox | None, unjoined: Sequence[str] = ()) -> list[str]:
    """netconvert's command line for the OSM file ``osm`` (without the output); the OSM
    nodes ``unjoined`` are not joined into junction clusters."""
    maps = sumo_home() / "data" / "typemap"
    args = ["--osm-files", str(osm), "--type-files", ",".join(str(maps / t) for t in TYPE_MAPS)]
    for opt in NETCONVERT_OPTIONS:
        args += [opt.name, opt.value]
    if bbox is not None:
        args += ["--keep-edges.in-geo-boundary", ",".join(repr(v) for v in bbox)]
    if unjoined:
        args += ["--junctions.join-exclude", ",".join(unjoined)]
    return args


def _convert(
    copy: Path, net: Path, source: Path, bbox: BBox | None, unjoined: Sequence[str]
) -> None:
    """Run netconvert on the repaired copy; HiyariError (one line) when it makes no net with
    a drivable lane."""
    inside = f" inside --bbox {','.join(f'{v:g}' for v in bbox)}" if bbox else ""
    try:
        run_sumo_tool("netconvert", [*netconvert_args(copy, bbox, unjoined), "-o", str(net)],
                      str(source))  # fmt: skip
    except HiyariError as exc:
        raise HiyariError(f"{exc}{inside}") from None
    if not net.is_file():
        raise HiyariError(f"{source}: netconvert made no network (no road{inside})")
    try:
        check_net(net)
    except HiyariError:
        raise HiyariError(f"{source}: the converted map has no drivable lanes{inside}") from None


def polyconvert_args(osm: Path, net: Path) -> list[str]:
    """polyconvert's command line for the areas of ``osm`` in the frame of ``net``."""
    types = sumo_home() / "data" / "typemap" / "osmPolyconvert.typ.xml"
    return [
        "--net-file", str(net), "--osm-files", str(osm), "--type-file", str(types),
        "--osm.keep-full-type", "true",  # type "building.<value>": the building tag's value
        "--osm.merge-relations", "1",  # multipolygon buildings assembled from their rings
        "--all-attributes", "true",  # every OSM tag as a param (height, building:levels ...)
        "--prune.in-net", "true",  # only what lies within the imported network
    ]  # fmt: skip


def import_osm(
    osm: str | Path,
    out: str | Path,
    options: OsmImportOptions | None = None,
    warn: Callable[[str], None] | None = None,
) -> Path:
    """Convert the OpenStreetMap extract ``osm`` to the SUMO net ``out``; return ``out``.

    With ``options.buildings`` the buildings go to ``poly_path(out)``. ``warn`` receives one
    line per repair of the extract and of the converted net. Raises HiyariError (one line) for a missing, truncated or
    malformed file, an extract without roads, a bounding box outside the map and a map that
    yields no drivable lane; nothing is written then, and the user's file is never modified.
    """
    opts = options or OsmImportOptions()
    source, out = Path(osm), Path(out)
    with tempfile.TemporaryDirectory(prefix="hiyari-net-") as tmp:
        work = Path(tmp)
        copy = work / "extract.osm"
        maps = sumo_home() / "data" / "typemap"
        streets = sidewalk_types(maps / "osmNetconvertPedestrians.typ.xml")
        repairs, extract = repair_osm(source, copy, streets)
        for r in repairs:
            (warn or _log.warning)(r.message(source))
        if opts.bbox is not None:
            check_bbox(source, opts.bbox, extract)
        net = work / "map.net.xml"
        _convert(copy, net, source, opts.bbox, ())
        say = warn or _log.warning
        unjoin = clusters_to_unjoin(net)
        if unjoin:
            for j, nodes in unjoin.items():
                say(f"{source}: junction {j}: OSM nodes {' '.join(nodes)} converted unjoined: "
                    "joined, their car links cross without being foes or pass closer than "
                    f"{CLOSE_PASS:g} m")  # fmt: skip
            _convert(copy, net, source, opts.bbox, [n for ns in unjoin.values() for n in ns])
        repair_net(net, str(source), lambda line: say(f"{source}: {line}"))
        poly = work / "map.poly.xml"
        if opts.buildings:
            run_sumo_tool("polyconvert", [*polyconvert_args(copy, net), "-o", str(poly)],
                          str(source))  # fmt: skip
        # both files appear together, the net last: a net is never beside a stale poly file
        if opts.buildings:
            with atomic_path(poly_path(out)) as dst:
                poly.replace(dst)
        with atomic_path(out) as dst:
            net.replace(dst)
    return out
