"""Generate SUMO networks from plain XML (nodes, edges, connections) with lxml and netconvert.

Five generators, each returning the written ``.net.xml`` path:

- ``build_intersection``: a four-leg intersection with sidewalks, crossings and an optional
  traffic light;
- ``build_city_grid``: a grid of signalised four-leg intersections with sidewalks, crossings
  and fringe arms;
- ``build_expressway``: a dual carriageway with N lanes, a clothoid-arc-clothoid curve of
  radius R with superelevation, an on-ramp merge, an off-ramp branch and guard rails;
- ``build_r157_road``: the UN R157 (Annex G) test road: two 3.5 m lanes, straight;
- ``build_catalogue_road``: the JAMA catalogue roads (main line, merge, branch, four-leg
  intersection) written as OpenDRIVE beside the net and imported with netconvert.

Geometry parameters use the JAMA Annex A road-geometry terms: lane width, curve radius,
transition section, cross slope (superelevation), longitudinal gradient. Lengths in metres,
speeds in m/s, slopes as fractions (0.06 = 6 %). Generated nets keep the authored coordinates
(no netconvert offset normalisation) except ``build_intersection``, which keeps netconvert's
normalised frame that earlier users rely on.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from hiyari.errors import HiyariError
from hiyari.net.sumo.expressway_layout import expressway_plain
from hiyari.net.sumo.plain_xml import build_net

#: netconvert options every generator uses: keep authored coordinates, no U-turns, write
#: coordinates in millimetres (cross slopes differ by centimetres between lanes).
_COMMON = [
    "--offset.disable-normalization",
    "true",
    "--no-turnarounds",
    "true",
    "--precision",
    "3",
]


def _param(default: object, doc: str):  # noqa: ANN202 - a dataclass field
    """A dataclass field whose ``doc`` metadata becomes the CLI help text."""
    return field(default=default, metadata={"doc": doc})


def param_docs(cls: type) -> dict[str, str]:
    """Field name -> documentation of a params dataclass."""
    return {f.name: f.metadata.get("doc", "") for f in fields(cls)}


@dataclass(frozen=True)
class IntersectionParams:
    """A four-leg intersection: arm length and lane width in metres, speed limit in m/s."""

    arm_length: float = _param(150.0, "length of each arm from the centre, m")
    lanes_per_direction: int = _param(1, "driving lanes per direction on each arm")
    lane_width: float = _param(3.5, "lane width, m")
    sidewalk_width: float = _param(2.0, "sidewalk width, m (0: no sidewalks)")
    speed_limit: float = _param(13.89, "speed limit, m/s")
    traffic_light: bool = _param(False, "signalise the intersection")
    crossings: bool = _param(True, "pedestrian crossings on every arm")
    crossing_width: float = _param(4.0, "width of the pedestrian crossings, m")
    tls_cycle: int = _param(90, "traffic-light cycle time, s")

    def validate(self) -> None:
        if self.arm_length < 20 or self.lane_width < 2.0 or self.lanes_per_direction < 1:
            raise HiyariError(
                "intersection: arm length >= 20 m, lane width >= 2 m, >= 1 lane per direction"
            )
        if self.crossings and self.sidewalk_width <= 0:
            raise HiyariError("intersection: crossings need sidewalks (sidewalk width > 0)")
        _positive("intersection", speed_limit=self.speed_limit, tls_cycle=self.tls_cycle)


def _positive(what: str, **values: float) -> None:
    for name, value in values.items():
        if not value > 0:
            raise HiyariError(f"{what}: {name} must be positive, got {value}")


def _urban_options(crossings: bool, crossing_width: float, tls_cycle: int) -> list[str]:
    opts = ["--walkingareas", "true", "--tls.cycle.time", str(tls_cycle)]
    if crossings:
        opts += ["--crossings.guess", "true", "--default.crossing-width", str(crossing_width)]
    return opts


def build_intersection(out: str | Path, params: IntersectionParams | None = None) -> Path:
    """Write a four-leg intersection with sidewalks and crossings to ``out`` (.net.xml).

    Centre node "C"; arm nodes "n", "e", "s", "w"; edges "<arm>_in" (towards the centre)
    and "<arm>_out". netconvert normalises the frame: the centre lies at (arm, arm).
    """
    p = params or IntersectionParams()
    p.validate()
    a = p.arm_length
    ends = {"n": (0, a), "e": (a, 0), "s": (0, -a), "w": (-a, 0)}
    ctype = "traffic_light" if p.traffic_light else "priority"
    nodes = [{"id": "C", "x": 0, "y": 0, "type": ctype}]
    nodes += [{"id": k, "x": x, "y": y, "type": "dead_end"} for k, (x, y) in ends.items()]
    common = {
        "numLanes": p.lanes_per_direction,
        "speed": p.speed_limit,
        "width": p.lane_width,
        "sidewalkWidth": p.sidewalk_width if p.sidewalk_width > 0 else None,
    }
    edges = []
    for k in ends:
        edges.append({"id": f"{k}_in", "from": k, "to": "C", **common})
        edges.append({"id": f"{k}_out", "from": "C", "to": k, **common})
    options = [
        "--no-turnarounds",
        "true",
        *_urban_options(p.crossings, p.crossing_width, p.tls_cycle),
    ]
    return build_net(out, nodes, edges, options, "intersection")


@dataclass(frozen=True)
class CityGridParams:
    """A grid of four-leg intersections (blocks_x x blocks_y blocks) with fringe arms."""

    blocks_x: int = _param(5, "blocks along x")
    blocks_y: int = _param(5, "blocks along y")
    block_length: float = _param(200.0, "distance between intersections, m")
    lanes_per_direction: int = _param(1, "driving lanes per direction")
    lane_width: float = _param(3.25, "lane width, m")
    sidewalk_width: float = _param(3.0, "sidewalk width, m")
    speed_limit: float = _param(13.89, "speed limit, m/s")
    traffic_lights: bool = _param(True, "signalise every grid intersection")
    crossings: bool = _param(True, "pedestrian crossings at every intersection")
    crossing_width: float = _param(4.0, "width of the pedestrian crossings, m")
    attach_length: float = _param(100.0, "length of the arms leaving the grid, m (0: none)")
    tls_cycle: int = _param(90, "traffic-light cycle time, s")

    def validate(self) -> None:
        if self.blocks_x < 1 or self.blocks_y < 1:
            raise HiyariError("city grid: blocks_x and blocks_y must be >= 1")
        if self.block_length < 40:
            raise HiyariError(f"city grid: block length must be >= 40 m, got {self.block_length}")
        if self.lane_width < 2.0 or self.lanes_per_direction < 1:
            raise HiyariError("city grid: lane width >= 2 m and >= 1 lane per direction")
        if self.sidewalk_width <= 0:
            raise HiyariError("city grid: sidewalk width must be positive")
        if self.attach_length < 0:
            raise HiyariError("city grid: attach length must be >= 0")
        _positive("city grid", speed_limit=self.speed_limit, tls_cycle=self.tls_cycle)


def city_grid_plain(p: CityGridParams) -> tuple[list[dict], list[dict], list[str]]:
    """Plain-XML nodes and edges of the city grid, and the netconvert options it needs."""
    p.validate()
    ctype = "traffic_light" if p.traffic_lights else "priority"
    nodes = [
        {"id": f"g{i}_{j}", "x": i * p.block_length, "y": j * p.block_length, "type": ctype}
        for i in range(p.blocks_x + 1)
        for j in range(p.blocks_y + 1)
    ]
    links = [((i, j), (i + 1, j)) for i in range(p.blocks_x) for j in range(p.blocks_y + 1)]
    links += [((i, j), (i, j + 1)) for i in range(p.blocks_x + 1) for j in range(p.blocks_y)]
    pairs = [(f"g{a[0]}_{a[1]}", f"g{b[0]}_{b[1]}") for a, b in links]
    if p.attach_length > 0:
        outward = []
        for i in range(p.blocks_x + 1):
            outward += [((i, 0), (0, -1)), ((i, p.blocks_y), (0, 1))]
        for j in range(p.blocks_y + 1):
            outward += [((0, j), (-1, 0)), ((p.blocks_x, j), (1, 0))]
        for (i, j), (dx, dy) in outward:
            arm = f"a{i}_{j}" + ("x" if dx else "y")
            x = i * p.block_length + dx * p.attach_length
            y = j * p.block_length + dy * p.attach_length
            nodes.append({"id": arm, "x": x, "y": y, "type": "dead_end"})
            pairs.append((f"g{i}_{j}", arm))
    common = {
        "numLanes": p.lanes_per_direction,
        "speed": p.speed_limit,
        "width": p.lane_width,
        "sidewalkWidth": p.sidewalk_width,
    }
    edges = []
    for a, b in pairs:
        edges.append({"id": f"{a}-{b}", "from": a, "to": b, **common})
        edges.append({"id": f"{b}-{a}", "from": b, "to": a, **common})
    options = [*_COMMON, *_urban_options(p.crossings, p.crossing_width, p.tls_cycle)]
    return nodes, edges, options


def build_city_grid(out: str | Path, params: CityGridParams | None = None) -> Path:
    """Write a city grid to ``out`` (.net.xml) and return its path.

    Grid nodes "g<i>_<j>" at (i * block, j * block); arm ends "a<i>_<j>x" / "a<i>_<j>y"
    outside the grid; edges "<from>-<to>" in both directions, each with a sidewalk on its
    right.
    """
    nodes, edges, options = city_grid_plain(params or CityGridParams())
    return build_net(out, nodes, edges, options, "city grid")


@dataclass(frozen=True)
class ExpresswayParams:
    """A dual carriageway along one alignment, with ramps on the eastbound carriageway.

    Stations are metres along the alignment from its start at (0, 0), heading +x. The
    eastbound carriageway lies right of the alignment, the westbound left, separated by the
    median. The curve is clothoid (transition) + arc + clothoid; superelevation ramps in
    linearly along the transitions from the normal cross slope (falling to the outside of
    each carriageway) to the full superelevation (falling towards the curve centre).
    """

    lanes: int = _param(2, "through lanes per direction")
    lane_width: float = _param(3.5, "lane width, m")
    length: float = _param(3000.0, "length of the main line, m")
    speed_limit: float = _param(27.78, "main-line speed limit, m/s (100 km/h)")
    curve_radius: float = _param(460.0, "radius of the circular arc, m (JAMA R_min at 100 km/h)")
    curve_length: float = _param(400.0, "length of the circular arc, m (0: straight road)")
    curve_start: float = _param(1000.0, "station where the entry transition starts, m")
    curve_left: bool = _param(True, "curve to the left (else to the right) going east")
    transition_length: float = _param(100.0, "clothoid / superelevation run-off length, m")
    cross_slope: float = _param(0.02, "normal cross slope on straights (fraction)")
    superelevation: float = _param(0.06, "cross slope on the arc (fraction, JAMA i = 6 %)")
    gradient: float = _param(0.0, "longitudinal gradient (fraction, + rising eastwards)")
    median_width: float = _param(3.0, "width between the carriageways' inner lane edges, m")
    shoulder_left: float = _param(0.75, "paved shoulder on the median side, m")
    shoulder_right: float = _param(2.5, "paved shoulder on the outer side, m")
    guard_rails: bool = _param(True, "guard rails along both sides of each carriageway")
    on_ramp: bool = _param(True, "add the on-ramp merge")
    merge_station: float = _param(
        500.0, "station where the on-ramp joins (acceleration lane start), m"
    )
    accel_length: float = _param(250.0, "acceleration lane length, m")
    off_ramp: bool = _param(True, "add the off-ramp branch")
    diverge_station: float = _param(
        2500.0, "station where the off-ramp leaves (deceleration lane end), m"
    )
    decel_length: float = _param(200.0, "deceleration lane length, m")
    ramp_length: float = _param(300.0, "length of each ramp alongside the main line, m")
    ramp_offset: float = _param(40.0, "lateral distance of each ramp's far end from its lane, m")
    ramp_speed: float = _param(16.67, "ramp speed limit, m/s (60 km/h)")
    shape_step: float = _param(2.0, "point spacing of lane shapes on curves, m")

    def validate(self) -> None:
        if self.lanes < 1 or self.lane_width < 2.5:
            raise HiyariError("expressway: >= 1 lane and lane width >= 2.5 m")
        _positive(
            "expressway",
            length=self.length,
            speed_limit=self.speed_limit,
            ramp_speed=self.ramp_speed,
            shape_step=self.shape_step,
            ramp_length=self.ramp_length,
            ramp_offset=self.ramp_offset,
        )
        half = self.median_width / 2 + (self.lanes + 1) * self.lane_width + self.shoulder_right
        if self.curve_length > 0:
            if self.curve_radius < max(30.0, 2 * half):
                raise HiyariError(
                    f"expressway: curve radius {self.curve_radius} m is too small for the "
                    f"cross-section (needs >= {max(30.0, 2 * half):.0f} m)"
                )
            if self.transition_length < 10:
                raise HiyariError("expressway: transition length must be >= 10 m")
            end = self.curve_start + 2 * self.transition_length + self.curve_length
            if self.curve_start < 0 or end > self.length:
                raise HiyariError(
                    f"expressway: the curve (stations {self.curve_start}..{end} m) must lie on the main line (0..{self.length} m)"
                )
        for name in ("cross_slope", "superelevation"):
            if not 0 <= getattr(self, name) <= 0.15:
                raise HiyariError(f"expressway: {name} must be within 0..0.15")
        if abs(self.gradient) > 0.12:
            raise HiyariError(
                f"expressway: gradient must be within -0.12..0.12, got {self.gradient}"
            )
        if min(self.median_width, self.shoulder_left, self.shoulder_right) < 0:
            raise HiyariError("expressway: median and shoulder widths must be >= 0")
        marks = [0.0]
        if self.on_ramp:
            marks += [
                self.merge_station - self.ramp_length,
                self.merge_station,
                self.merge_station + self.accel_length,
            ]
        if self.off_ramp:
            marks += [
                self.diverge_station - self.decel_length,
                self.diverge_station,
                self.diverge_station + self.ramp_length,
            ]
        marks.append(self.length)
        if np.any(np.diff(marks) <= 0):
            raise HiyariError(
                "expressway: stations must increase along the main line: on-ramp start, merge, "
                "acceleration lane end, deceleration lane start, diverge, off-ramp end, length"
            )


def build_expressway(out: str | Path, params: ExpresswayParams | None = None) -> Path:
    """Write an expressway to ``out`` (.net.xml) and return its path.

    Eastbound edges in order: "east_in", "east_nose", "east_merge" (the acceleration lane is
    lane 0), "east_mid", "east_diverge" (the deceleration lane is lane 0), "east_gore",
    "east_out"; ramps "onramp" (joins east_merge lane 0) and "offramp" (leaves from
    east_diverge lane 0); the westbound carriageway is the one edge "west". Lane 0 is the
    rightmost lane. Without the on-ramp, east_nose / east_merge / east_mid are left out;
    without the off-ramp, east_diverge / east_gore; without both, the eastbound carriageway
    is the one edge "east". Nose and gore edges carry no outer rail (the ramp runs beside).
    """
    p = params or ExpresswayParams()
    p.validate()
    nodes, edges, connections = expressway_plain(p)
    return build_net(out, nodes, edges, _COMMON, "expressway", connections)


@dataclass(frozen=True)
class R157RoadParams:
    """The UN R157 Annex G test road: straight, two lanes, one direction (+x).

    Edge "road" from node "start" at (0, 0) to node "end" at (length, 0). Lane "road_0" is
    the right lane (centre y = -lane_width / 2), "road_1" the left lane (centre
    y = +lane_width / 2).
    """

    length: float = _param(3000.0, "road length, m")
    lane_width: float = _param(3.5, "lane width, m (Annex G: 3.5)")
    speed_limit: float = _param(36.11, "speed limit, m/s (130 km/h)")
    gradient: float = _param(0.0, "longitudinal gradient (fraction; Annex G: 0)")
    guard_rails: bool = _param(False, "guard rails along both road edges")

    def validate(self) -> None:
        if self.length < 100:
            raise HiyariError(f"r157 road: length must be >= 100 m, got {self.length}")
        if self.lane_width < 2.5:
            raise HiyariError(f"r157 road: lane width must be >= 2.5 m, got {self.lane_width}")
        _positive("r157 road", speed_limit=self.speed_limit)
        if abs(self.gradient) > 0.12:
            raise HiyariError(
                f"r157 road: gradient must be within -0.12..0.12, got {self.gradient}"
            )


def build_r157_road(out: str | Path, params: R157RoadParams | None = None) -> Path:
    """Write the two-lane R157 road to ``out`` (.net.xml) and return its path."""
    p = params or R157RoadParams()
    p.validate()
    nodes = [
        {"id": "start", "x": 0.0, "y": 0.0, "z": 0.0, "type": "dead_end"},
        {"id": "end", "x": p.length, "y": 0.0, "z": p.gradient * p.length, "type": "dead_end"},
    ]
    side = "left right" if p.guard_rails else "none"
    edge = {
        "id": "road",
        "from": "start",
        "to": "end",
        "numLanes": 2,
        "width": p.lane_width,
        "speed": p.speed_limit,
        "spreadType": "center",
        "params": {"hiyari:barrier": side},
    }
    return build_net(out, nodes, [edge], _COMMON, "r157 road")


@dataclass(frozen=True)
class CatalogueRoadParams:
    """A JAMA catalogue road as OpenDRIVE (written beside the net as .xodr), then imported.

    Main line / merge / branch: one carriageway along +x, road "main", lanes -1 (leftmost)
    to -lanes, merge / exit lane -(lanes + 1); intersection: four legs, one lane per direction
    (see hiyari.net.road.xodr_writer).
    """

    lanes: int = _param(2, "through lanes per direction (motorway: 2 or 3; intersection: 1)")
    lane_width: float = _param(3.5, "lane width, m")
    length: float = _param(1500.0, "motorway road length, m")
    station: float = _param(
        700.0, "merge: end of the acceleration lane; branch: exit lane start, m"
    )


def build_catalogue_road(
    out: str | Path, params: CatalogueRoadParams | None = None, geometry: str = "main"
) -> Path:
    """Write ``out`` (.net.xml) and the OpenDRIVE road beside it (``out`` with .xodr) for a
    catalogue ``geometry`` (main, merge, branch, intersection); return the net's path."""
    from hiyari.net.road.xodr_writer import CatalogueRoad, write_catalogue_road
    from hiyari.net.sumo.opendrive import import_opendrive

    params = params or CatalogueRoadParams()
    road = CatalogueRoad(
        geometry=geometry,
        lanes=1 if geometry == "intersection" else params.lanes,
        lane_width=params.lane_width,
        length=params.length,
        merge_end=params.station,
        branch_start=params.station,
    )
    out = Path(out)
    xodr = write_catalogue_road(xodr_beside(out), road)
    return import_opendrive(xodr, out, warn=lambda _msg: None)


def xodr_beside(net: str | Path) -> Path:
    """The OpenDRIVE file written next to a generated net: ``x.net.xml`` -> ``x.xodr``."""
    net = Path(net)
    stem = net.name.removesuffix(".net.xml").removesuffix(".xml")
    return net.with_name(stem + ".xodr")
