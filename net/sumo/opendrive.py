"""Import an OpenDRIVE (.xodr) map into a SUMO net with netconvert, keeping elevation.

The net keeps the OpenDRIVE coordinates (no offset normalisation: net x, y = OpenDRIVE x, y)
and the elevation profile (z). Lane ids follow netconvert: edge "<road id>" for lanes on the
left of the reference line (driving against the road direction) and "-<road id>" for the right
lanes, split per lane section as "<id>#<k>" (k = 0, 1, ...) where a road has several; lane
index 0 is the outermost imported lane.
By default netconvert imports the lane types vehicles and pedestrians use (driving, stop /
shoulder, sidewalk, biking ...); ``ImportOptions.all_lanes`` adds every type (border, median,
...) as lanes no vehicle may use, which the scene mesh draws as verge.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.net.sumo.files import check_net
from hiyari.sumo_tools import run_sumo_tool


@dataclass(frozen=True)
class ImportOptions:
    """How netconvert reads the OpenDRIVE file."""

    all_lanes: bool = False  # import every lane type, not only the ones traffic uses
    curve_resolution: float = 2.0  # point spacing along curved geometry, m
    internal_shapes: bool = True  # take junction lane shapes from the file's junction roads


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


def import_opendrive(
    xodr: str | Path, out: str | Path, options: ImportOptions | None = None
) -> Path:
    """Convert ``xodr`` to the SUMO net ``out``; return ``out``.

    Raises HiyariError (one line) for a missing, malformed or invalid file and for a map
    without drivable lanes; ``out`` is then left untouched.
    """
    opts = options or ImportOptions()
    if opts.curve_resolution <= 0:
        raise HiyariError(f"curve resolution must be positive, got {opts.curve_resolution} m")
    check_opendrive(xodr)
    args = [
        "--opendrive-files",
        str(xodr),
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
    ]
    if opts.internal_shapes:
        args += ["--opendrive.internal-shapes", "true"]
    if opts.all_lanes:
        args += ["--opendrive.import-all-lanes", "true"]
    with atomic_path(out) as target:
        run_sumo_tool("netconvert", [*args, "-o", str(target)], str(xodr))
        try:
            check_net(target)
        except HiyariError:
            raise HiyariError(f"{xodr}: the converted map has no drivable lanes") from None
    return Path(out)
