"""Import an OpenDRIVE (.xodr) map into a SUMO net with netconvert, as its author meant it.

Coordinates and elevation: the net keeps the OpenDRIVE coordinates (no offset normalisation:
net x, y = OpenDRIVE x, y) and the elevation profile (z).

Ids: edge "<road id>" for lanes on the left of the reference line (driving against the road
direction) and "-<road id>" for the right lanes, split per lane section as "<id>#<k>" where a
road has several; lane index 0 is the outermost imported lane. Every lane keeps its OpenDRIVE
identity in ``<param key="origId" value="<road>_<lane>"/>`` and its lane type in ``type``.

Lane types: who may use each lane and whether it is imported by default come from the one
table in ``hiyari.net.sumo.lane_types`` (driving lanes for vehicles; shoulders and parking in
the net but closed to ordinary traffic; sidewalks for pedestrians, imported by default; verge
types such as border or median only with ``ImportOptions.all_lanes``, closed to all).

Repairs: valid OpenDRIVE that netconvert refuses is repaired on a temporary copy first
(``hiyari.net.sumo.opendrive_repair``); each repair is reported through ``warn``.

Direct junctions: their lane links in the net are exactly the file's ``laneLink``s, in the
lanes' driving directions (``hiyari.net.sumo.direct_junctions``; a second netconvert run with
a connection file when netconvert's own reading differs).

Junction shapes: by default the lanes inside junctions follow the file's connecting roads
(the author's geometry). When SUMO's junction logic then disagrees with those paths (links it
lets pass unhindered cross, or links it makes wait neither cross nor merge; see
``hiyari.net.sumo.junction_check``) and netconvert's own computed shapes agree better, or when
netconvert fails with the file's shapes, the computed shapes are used, with one warning.
"""

from __future__ import annotations

import logging
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.net.sumo.direct_junctions import (
    DirectJunction,
    compare_links,
    direct_junctions,
    write_connections,
)
from hiyari.net.sumo.files import check_net
from hiyari.net.sumo.junction_check import JunctionReport, check_junctions
from hiyari.net.sumo.lane_types import write_type_map
from hiyari.net.sumo.opendrive_repair import repair_opendrive
from hiyari.sumo_tools import run_sumo_tool

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ImportOptions:
    """How netconvert reads the OpenDRIVE file."""

    all_lanes: bool = False  # also import verge lane types (border, median, ...), closed to all
    curve_resolution: float = 2.0  # point spacing along curved geometry, m
    internal_shapes: bool | None = None  # junction lanes: file's shapes (True), computed
    # (False), or None: the file's unless the junction check prefers the computed ones


def check_opendrive(path: str | Path) -> etree._Element:
    """Parse and sanity-check an OpenDRIVE file; HiyariError naming the file and the problem."""
    path = Path(path)
    if not path.is_file():
        raise HiyariError(f"{path}: OpenDRIVE file not found")
    try:
        root = etree.parse(str(path), etree.XMLParser(huge_tree=True)).getroot()
    except etree.XMLSyntaxError as exc:
        raise HiyariError(f"{path}: not well-formed XML: {exc.msg}") from None
    if etree.QName(root).localname != "OpenDRIVE":
        raise HiyariError(f"{path}: not an OpenDRIVE file (root element <{root.tag}>)")
    roads = root.findall("road")
    if not roads:
        raise HiyariError(f"{path}: OpenDRIVE file has no <road>")
    for road in roads:
        rid = road.get("id", "?")
        if not road.findall("planView/geometry"):
            raise HiyariError(f"{path}: road {rid} has no planView geometry")
        if not road.findall("lanes/laneSection"):
            raise HiyariError(f"{path}: road {rid} has no lane section")
        for geom in road.findall("planView/geometry"):
            try:
                length = float(geom.get("length", "nan"))
            except ValueError:
                length = float("nan")
            if not length > 0:
                raise HiyariError(
                    f"{path}: road {rid} has a geometry with an invalid length {geom.get('length')!r}"
                )
    return root


def _netconvert_args(xodr: Path, types: Path, opts: ImportOptions, shapes: bool) -> list[str]:
    args = [
        "--opendrive-files",
        str(xodr),
        "--type-files",
        str(types),
        "--offset.disable-normalization",
        "true",
        "--no-turnarounds",
        "true",
        "--precision",
        "3",
        "--opendrive.curve-resolution",
        repr(opts.curve_resolution),
        # every lane keeps its OpenDRIVE identity ("<road id>_<lane id>" in param origId) and
        # lane type, so road / lane / s positions map onto SUMO lanes without guessing
        "--output.original-names",
        "true",
        "--opendrive.internal-shapes",
        "true" if shapes else "false",
        # pedestrians need walking areas to get from one sidewalk to the next at junctions
        "--walkingareas",
        "true",
    ]
    if opts.all_lanes:
        args += ["--opendrive.import-all-lanes", "true"]
    return args


def _convert(xodr: Path, source: Path, types: Path, opts: ImportOptions, shapes: bool,
             target: Path, direct: list[DirectJunction]) -> JunctionReport:  # fmt: skip
    """One netconvert run into ``target`` (a second one with a connection file when the
    direct junctions' links differ from the file's); the junction check of the result."""
    args = [*_netconvert_args(xodr, types, opts, shapes), "-o", str(target)]
    run_sumo_tool("netconvert", args, str(source))
    try:
        check_net(target)
    except HiyariError:
        raise HiyariError(f"{source}: the converted map has no drivable lanes") from None
    patch = compare_links(target, direct)
    if patch:
        connections = write_connections(patch, target.with_suffix(".con.xml"))
        run_sumo_tool("netconvert", [*args, "--connection-files", str(connections)], str(source))
        left = compare_links(target, direct)
        if left:
            raise HiyariError(f"{source}: netconvert keeps direct-junction links the file does "
                              f"not have {list(left.extra)} or lacks {list(left.missing)}")  # fmt: skip
    return check_junctions(target)


def _choose_shapes(xodr: Path, source: Path, types: Path, opts: ImportOptions, work: Path,
                   warn: Callable[[str], None], direct: list[DirectJunction]) -> Path:  # fmt: skip
    """Convert with the file's junction shapes, falling back to computed ones (see module)."""
    first = opts.internal_shapes if opts.internal_shapes is not None else True
    compare = opts.internal_shapes is None  # an explicit choice only falls back on failure
    results: dict[bool, tuple[Path, JunctionReport] | HiyariError] = {}
    for shapes in (first, not first):
        net = work / f"shapes-{shapes}.net.xml"
        try:
            results[shapes] = (net, _convert(xodr, source, types, opts, shapes, net, direct))
        except HiyariError as exc:
            results[shapes] = exc
        done = results[shapes]
        if not isinstance(done, HiyariError) and (done[1].clean or not compare):
            break
    chosen = results[first]
    other = results.get(not first)
    name = {True: "the file's junction shapes", False: "netconvert's computed junction shapes"}
    if isinstance(chosen, HiyariError):
        if other is None or isinstance(other, HiyariError):
            raise chosen
        warn(f"{source}: netconvert failed with {name[first]} ({chosen}); using {name[not first]}")
        return other[0]
    if other is None or isinstance(other, HiyariError):
        return chosen[0]
    if len(other[1].unregulated) < len(chosen[1].unregulated) or (
        not other[1].unregulated and not chosen[1].unregulated
        and len(other[1].phantom) < len(chosen[1].phantom)
    ):  # fmt: skip
        warn(f"{source}: {name[first]} disagree with SUMO's junction logic "
             f"({chosen[1].summary()}); using {name[not first]} ({other[1].summary()})")  # fmt: skip
        return other[0]
    return chosen[0]


def import_opendrive(
    xodr: str | Path,
    out: str | Path,
    options: ImportOptions | None = None,
    warn: Callable[[str], None] | None = None,
) -> Path:
    """Convert ``xodr`` to the SUMO net ``out``; return ``out``.

    ``warn`` receives one line per repair of the file and per junction-shape fallback
    (default: this module's logger). Raises HiyariError (one line) for a missing, malformed
    or invalid file and for a map without drivable lanes; ``out`` is then left untouched and
    the user's file is never modified.
    """
    opts = options or ImportOptions()
    warn = warn or _log.warning
    if not opts.curve_resolution > 0:
        raise HiyariError(f"curve resolution must be positive, got {opts.curve_resolution} m")
    xodr = Path(xodr)
    root = check_opendrive(xodr)
    lane_types = {ln.get("type", "") for ln in root.iter("lane")} - {""}
    with tempfile.TemporaryDirectory(prefix="hiyari-net-") as tmp:
        work = Path(tmp)
        repaired = work / xodr.name
        for repair in repair_opendrive(xodr, repaired):
            warn(repair.message(xodr))
        types = write_type_map(work / "opendrive.typ.xml", lane_types)
        direct = direct_junctions(root)
        net = _choose_shapes(repaired, xodr, types, opts, work, warn, direct)
        for link in compare_links(net, direct).unusable:
            warn(f"{xodr}: {link}: both lanes enter or both leave the junction: not imported")
        with atomic_path(out) as target:
            target.write_bytes(net.read_bytes())
    return Path(out)
