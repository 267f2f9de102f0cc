"""OpenDRIVE road / lane / s / offset <-> world x, y, heading, and <-> the SUMO lanes of a net
imported with ``hiyari net import`` (netconvert with ``--output.original-names``).

The reference line is evaluated from the .xodr itself (line, arc, spiral, poly3, paramPoly3),
with the lane offset and lane width polynomials, so positions are exact rather than read off
SUMO's polylines. Which SUMO lane holds an OpenDRIVE lane is never guessed: every imported lane
carries ``param origId = "<road id>_<lane id>"``, and its edge is ``"<road>"`` / ``"-<road>"``,
suffixed ``"#k"`` with the lane section index k when the road has several sections; the
sections' s ranges come from the .xodr.

Frames and units: OpenDRIVE = network coordinates (the import keeps them: no offset), metres;
``s`` along the road's reference line, ``t`` to its left; headings in radians counter-clockwise
from +x. ``offset`` (OpenSCENARIO LanePosition) is measured from the lane's centre line in the
road's t direction. A lane's driving direction is +s for right lanes (negative ids) on
right-hand-traffic roads and -s for left lanes (LHT: the reverse).
"""

from __future__ import annotations

import math
from bisect import bisect_right
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np
from lxml import etree
from scipy.spatial import cKDTree

from hiyari.errors import HiyariError
from hiyari.net.road.lane_profile import LaneProfile, lane_centre_at, lane_centres, lane_profile
from hiyari.net.road.plan_view import PlanView, line_arc_poses, plan_view
from hiyari.net.sumo.files import check_net
from hiyari.net.sumo.opendrive import check_opendrive

#: Gauss-Legendre nodes per sub-interval when integrating a spiral's heading.
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(24)
#: Largest heading change integrated by one Gauss-Legendre sub-interval, rad.
_GL_MAX_TURN = 1.0
#: Spacing of the reference-line samples used to seed the inverse (world -> road), m.
_SEED_STEP = 1.0


@dataclass(frozen=True)
class Poly3:
    """a + b ds + c ds^2 + d ds^3, valid from ``s0`` (ds = s - s0)."""

    s0: float
    a: float
    b: float
    c: float
    d: float

    def __call__(self, s: np.ndarray) -> np.ndarray:
        ds = s - self.s0
        return self.a + ds * (self.b + ds * (self.c + ds * self.d))


def _piecewise_at(records: tuple[Poly3, ...], s: float) -> float:
    """``_piecewise`` for one s (pure Python: cheaper than numpy for a scalar)."""
    if not records:
        return 0.0
    k = max(0, bisect_right([r.s0 for r in records], s) - 1) if len(records) > 1 else 0
    r = records[k]
    ds = s - r.s0
    return r.a + ds * (r.b + ds * (r.c + ds * r.d))


def _piecewise(records: tuple[Poly3, ...], s: np.ndarray) -> np.ndarray:
    """Evaluate piecewise cubic records (sorted by s0) at ``s``; 0 where none applies."""
    if not records:
        return np.zeros_like(s)
    starts = np.array([r.s0 for r in records])
    k = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(records) - 1)
    if len(records) == 1:
        return records[0](s)
    out = np.empty_like(s)
    for i in np.unique(k):
        m = k == i
        out[m] = records[i](s[m])
    return out


@dataclass(frozen=True)
class Geometry:
    """One planView record: starts at road ``s0`` at (x, y) heading ``hdg``, ``length`` m."""

    s0: float
    x: float
    y: float
    hdg: float
    length: float
    kind: str  # line, arc, spiral, poly3, paramPoly3
    params: tuple[float, ...] = ()  # arc: (k,); spiral: (k0, k1); poly3: (a, b, c, d);
    # paramPoly3: (aU, bU, cU, dU, aV, bV, cV, dV, normalized 0/1)
    table: tuple[np.ndarray, np.ndarray] | None = None  # poly3: (arc length, u) samples

    def pose(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, heading) at distance ``u`` (m) from the start along this geometry."""
        if self.kind in ("line", "arc"):
            k = self.params[0] if self.kind == "arc" else 0.0
            return line_arc_poses(self.x, self.y, self.hdg, k, np.asarray(u, dtype=float))
        if self.kind == "spiral":
            return self._spiral(u)
        if self.kind == "poly3":
            a, b, c, d = self.params
            lu = np.interp(u, self.table[0], self.table[1])
            v = a + lu * (b + lu * (c + lu * d))
            dv = b + lu * (2 * c + 3 * d * lu)
            return self._local(lu, v, np.arctan(dv))
        a_u, b_u, c_u, d_u, a_v, b_v, c_v, d_v, normalized = self.params
        p = u / self.length if normalized else u
        uu = a_u + p * (b_u + p * (c_u + p * d_u))
        vv = a_v + p * (b_v + p * (c_v + p * d_v))
        du = b_u + p * (2 * c_u + 3 * d_u * p)
        dv = b_v + p * (2 * c_v + 3 * d_v * p)
        return self._local(uu, vv, np.arctan2(dv, du))

    def _local(self, u: np.ndarray, v: np.ndarray, dh: np.ndarray):
        c, s = math.cos(self.hdg), math.sin(self.hdg)
        return self.x + u * c - v * s, self.y + u * s + v * c, self.hdg + dh

    def _spiral(self, u: np.ndarray):
        k0, k1 = self.params
        dk = (k1 - k0) / self.length
        turn = abs(k0) * self.length + 0.5 * abs(dk) * self.length**2
        n_sub = max(1, math.ceil(turn / _GL_MAX_TURN))
        # integrate cos/sin of the heading over [0, u] with n_sub Gauss-Legendre pieces
        edges = np.linspace(0.0, 1.0, n_sub + 1)
        half = 0.5 * (edges[1:] - edges[:-1])
        mid = 0.5 * (edges[1:] + edges[:-1])
        frac = (mid[:, None] + half[:, None] * _GL_NODES[None, :]).ravel()
        wts = (half[:, None] * _GL_WEIGHTS[None, :]).ravel()
        v = u[:, None] * frac[None, :]
        h = self.hdg + k0 * v + 0.5 * dk * v * v
        x = self.x + u * (np.cos(h) @ wts)
        y = self.y + u * (np.sin(h) @ wts)
        return x, y, self.hdg + k0 * u + 0.5 * dk * u * u


@dataclass(frozen=True)
class LaneSpec:
    """One lane of a lane section: id, type and width records (s0 relative to the section)."""

    id: int
    type: str
    widths: tuple[Poly3, ...]


@dataclass(frozen=True)
class LaneSection:
    """Lanes valid from road ``s0`` to ``s1``."""

    index: int
    s0: float
    s1: float
    lanes: dict[int, LaneSpec]


@dataclass(frozen=True, eq=False)
class Road:
    """One OpenDRIVE road: reference line, lane offset, lane sections, elevation."""

    id: str
    length: float
    geometries: tuple[Geometry, ...]
    lane_offset: tuple[Poly3, ...]
    sections: tuple[LaneSection, ...]
    elevation: tuple[Poly3, ...]
    left_hand: bool  # rule="LHT"

    def reference(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, heading) of the reference line at road ``s`` (clamped to the road), m / rad."""
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        starts = np.array([g.s0 for g in self.geometries])
        k = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(starts) - 1)
        x, y, h = np.empty_like(s), np.empty_like(s), np.empty_like(s)
        for i in np.unique(k):
            g, m = self.geometries[i], k == i
            x[m], y[m], h[m] = g.pose(s[m] - g.s0)
        return x, y, h

    def section_at(self, s: float) -> int:
        """Index of the lane section that holds road ``s`` (scalar)."""
        if len(self.sections) == 1:
            return 0
        return max(0, bisect_right([sec.s0 for sec in self.sections], s) - 1)

    @cached_property
    def straight(self) -> bool:
        """Whether the reference line is made of straight lines only."""
        return all(g.kind == "line" for g in self.geometries)

    @cached_property
    def plan_view(self) -> PlanView | None:
        """This road's reference line and elevation as arrays (None: not lines and arcs)."""
        return plan_view(self)

    @cached_property
    def profile(self) -> LaneProfile:
        """This road's lane offset and lane widths as arrays (road index 0)."""
        return lane_profile((self,))

    def lane_t(self, lane_id: int, s: float) -> float:
        """t of lane ``lane_id``'s centre line at road ``s`` (scalar ``lane_centre_t``)."""
        if lane_id == 0:  # the centre lane: the lane offset's line, no width
            return _piecewise_at(self.lane_offset, float(s))
        t, _, missing = lane_centre_at(*self.profile.arrays(), 0, int(lane_id), float(s))
        if missing >= 0:
            self._no_lane(lane_id, missing)
        return t

    def section_index(self, s: np.ndarray) -> np.ndarray:
        """Index of the lane section that holds road ``s``."""
        starts = np.array([sec.s0 for sec in self.sections])
        return np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(starts) - 1)

    def lane_centre_t(self, lane_id: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(t of the lane's centre line, lane width) at road ``s``, metres. Lane 0 (the
        centre lane, OpenDRIVE's reference for the lane ids) is the road's reference line
        moved by the lane offset, 0 m wide."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        if lane_id == 0:
            return _piecewise(self.lane_offset, s), np.zeros_like(s)
        t, width, missing = lane_centres(*self.profile.arrays(), 0, int(lane_id), s)
        if missing >= 0:
            self._no_lane(lane_id, missing)
        return t, width

    def _no_lane(self, lane_id: int, section: int) -> None:
        raise HiyariError(
            f"road {self.id} has no lane {lane_id} in its lane section at "
            f"s = {self.sections[section].s0:g} m"
        )

    def boundaries(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """Lane ids (outermost right ... outermost left, no 0) and their (n, 2) [right, left]
        t bounds at road ``s``."""
        sec = self.sections[self.section_at(s)]
        base = _piecewise_at(self.lane_offset, s)
        ds = s - sec.s0
        ids, bounds = [], []
        for side in (-1, 1):
            edge = base
            for j in range(1, 1 + max((abs(i) for i in sec.lanes if i * side > 0), default=0)):
                spec = sec.lanes.get(side * j)
                w = _piecewise_at(spec.widths, ds) if spec is not None else 0.0
                lo, hi = (edge - w, edge) if side < 0 else (edge, edge + w)
                ids.append(side * j)
                bounds.append((lo, hi))
                edge = lo if side < 0 else hi
        order = np.argsort([b[0] for b in bounds])
        return np.array(ids)[order], np.array(bounds).reshape(-1, 2)[order]

    def z(self, s: np.ndarray) -> np.ndarray:
        """Height of the reference line at road ``s`` (elevation profile), m."""
        return _piecewise(self.elevation, np.asarray(s, dtype=float))

    def drives_forward(self, lane_id: int) -> bool:
        """True when traffic on ``lane_id`` moves towards increasing s."""
        return (lane_id < 0) != self.left_hand


@dataclass(frozen=True)
class RoadCoord:
    """A point in road coordinates: road, lane, s (m), offset from the lane centre and t (m)."""

    road: str
    lane: int
    s: float
    offset: float
    t: float


@dataclass(frozen=True)
class Placement:
    """A road / lane / s / offset position resolved on the map and on the SUMO net.

    ``x``, ``y``, ``z`` in network metres; ``heading`` the lane's driving direction (rad CCW
    from +x); ``road_heading`` the reference line's (+s) direction; ``sumo_lane`` '' when the
    OpenDRIVE lane was not imported into SUMO (for example a border lane); ``pos`` metres along
    the SUMO lane (SUMO's own length measure); ``lateral`` metres left of its centre line.
    """

    x: float
    y: float
    z: float
    heading: float
    road_heading: float
    sumo_lane: str
    sumo_edge: str
    lane_index: int
    pos: float
    lateral: float


@dataclass(frozen=True, eq=False)
class SumoLane:
    """A SUMO lane with the OpenDRIVE identity netconvert kept."""

    id: str
    edge: str
    index: int
    length: float  # SUMO's lane length, m
    shape: np.ndarray  # (n, 2)
    cum: np.ndarray  # (n,) distance along the shape, m

    @staticmethod
    def from_shape(
        lane_id: str, edge: str, index: int, shape: np.ndarray, length: float | None = None
    ) -> SumoLane:
        """A lane with its polyline ``shape`` (n, 2), m; ``length``: SUMO's (None: the
        polyline's)."""
        cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(shape, axis=0), axis=1))])
        return SumoLane(lane_id, edge, index, cum[-1] if length is None else length, shape, cum)


@dataclass(frozen=True, eq=False)
class OpenDriveMap:
    """The roads of one .xodr file, keyed by road id."""

    path: Path
    roads: dict[str, Road]
    _seeds: tuple = field(repr=False)  # KD-trees of 1 m reference-line samples

    @staticmethod
    def from_file(path: str | Path) -> OpenDriveMap:
        """Read ``path``; HiyariError naming the file for a missing or unsupported map."""
        root = check_opendrive(path)
        roads = {}
        for el in root.findall("road"):
            road = _read_road(Path(path), el)
            roads[road.id] = road
        return OpenDriveMap.from_roads(path, roads)

    @staticmethod
    def from_roads(path: str | Path, roads: dict[str, Road]) -> OpenDriveMap:
        """The map of ``roads`` (keyed by id); ``path`` names where they came from."""
        pts, owner, s_of = [], [], []
        for k, road in enumerate(roads.values()):
            s = np.linspace(0.0, road.length, max(2, math.ceil(road.length / _SEED_STEP) + 1))
            x, y, _ = road.reference(s)
            pts.append(np.column_stack([x, y]))
            owner.append(np.full(len(s), k))
            s_of.append(s)
        per_road = {rid: (cKDTree(p), so) for rid, p, so in zip(roads, pts, s_of, strict=True)}
        seeds = (
            cKDTree(np.concatenate(pts)),
            np.concatenate(owner),
            np.concatenate(s_of),
            per_road,
        )
        return OpenDriveMap(Path(path), roads, seeds)

    def road(self, road_id: str) -> Road:
        """The road ``road_id``; HiyariError when the map has none."""
        try:
            return self.roads[str(road_id)]
        except KeyError:
            raise HiyariError(f"{self.path}: no road with id {road_id!r}") from None

    def lane_pose(
        self, road_id: str, lane_id: int, s: np.ndarray, offset: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, z, road heading) of points ``offset`` m (road t direction) from the centre of
        lane ``lane_id`` at road ``s``."""
        road = self.road(road_id)
        s = np.atleast_1d(np.asarray(s, dtype=float))
        t, _ = road.lane_centre_t(int(lane_id), s)
        return self.road_pose(road_id, s, t + offset)

    def road_pose(
        self, road_id: str, s: np.ndarray, t: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, z, reference-line heading) at road ``s``, lateral ``t`` (m)."""
        road = self.road(road_id)
        s = np.atleast_1d(np.asarray(s, dtype=float))
        x, y, h = road.reference(s)
        return x - t * np.sin(h), y + t * np.cos(h), road.z(s), h

    def locate(self, x: np.ndarray, y: np.ndarray, road_id: str | None = None) -> list[RoadCoord]:
        """Road coordinates of world points (the nearest road's reference line, or ``road_id``'s).

        s is found by Newton steps on the exact reference line from the nearest 1 m sample;
        the lane is the one whose borders hold t (the outermost lane beyond the road's edge).
        """
        x = np.atleast_1d(np.asarray(x, dtype=float))
        y = np.atleast_1d(np.asarray(y, dtype=float))
        tree, owner, s_seed, per_road = self._seeds
        names = list(self.roads)
        if road_id is None:
            _, k = tree.query(np.column_stack([x, y]))
            road_ix, s = owner[k], s_seed[k].copy()
        else:
            road = self.road(road_id)
            sub, sub_s = per_road[road.id]
            _, k = sub.query(np.column_stack([x, y]))
            road_ix, s = np.full(len(x), names.index(road.id)), sub_s[k].copy()
        out: list[RoadCoord | None] = [None] * len(x)
        for r in np.unique(road_ix):
            road = self.roads[names[r]]
            m = np.flatnonzero(road_ix == r)
            sr, tr = _project(road, x[m], y[m], s[m])
            for j, sj, tj in zip(m, sr, tr, strict=True):
                out[j] = _lane_coord(road, float(sj), float(tj))
        return out  # type: ignore[return-value]

    def locate_near(self, road_id: str, x: float, y: float, s_guess: float) -> RoadCoord:
        """Road coordinates of the point (``x``, ``y``) on road ``road_id`` by Newton steps from
        ``s_guess`` (a nearby s, such as the point's s one simulation step earlier), without
        the nearest-sample search of :meth:`locate`."""
        road = self.road(road_id)
        s, t = _project(road, np.array([float(x)]), np.array([float(y)]), np.array([s_guess]))
        return _lane_coord(road, float(s[0]), float(t[0]))


def _project(road: Road, x: np.ndarray, y: np.ndarray, s: np.ndarray):
    """Newton iterations for the foot point of (x, y) on the road's reference line."""
    for _ in range(8):
        rx, ry, h = road.reference(s)
        c, sn = np.cos(h), np.sin(h)
        ds = (x - rx) * c + (y - ry) * sn
        t = -(x - rx) * sn + (y - ry) * c
        if np.all(np.abs(ds) < 1e-9):
            break
        s = np.clip(s + ds, 0.0, road.length)
    return s, t


def _lane_coord(road: Road, s: float, t: float) -> RoadCoord:
    ids, bounds = road.boundaries(s)
    if len(ids) == 0:
        return RoadCoord(road.id, 0, s, t, t)
    inside = np.flatnonzero((bounds[:, 0] <= t) & (t <= bounds[:, 1]))
    k = int(inside[0]) if inside.size else (0 if t < bounds[0, 0] else len(ids) - 1)
    centre = 0.5 * (bounds[k, 0] + bounds[k, 1])
    return RoadCoord(road.id, int(ids[k]), s, t - centre, t)


class RoadLanes:
    """An OpenDRIVE map and the SUMO net imported from it, linked lane by lane."""

    def __init__(
        self,
        odr: OpenDriveMap,
        net: str | Path,
        links: tuple[dict[tuple[str, int, int], SumoLane], dict[str, list[str]]] | None = None,
    ) -> None:
        """``links``: the SUMO lane of each (road, lane, section) and each edge's successors
        (None: read from the lanes' origId in ``net``)."""
        self.odr = odr
        self.net = Path(net)
        self._lanes, self._next = links if links is not None else _sumo_lanes(self.net)
        self._by_id = {ln.id: key for key, ln in self._lanes.items()}

    @staticmethod
    def from_files(xodr: str | Path, net: str | Path) -> RoadLanes:
        """Link ``xodr`` with the SUMO ``net`` imported from it."""
        return RoadLanes(OpenDriveMap.from_file(xodr), net)

    def sumo_lane(self, road_id: str, lane_id: int, s: float) -> SumoLane | None:
        """The SUMO lane that carries OpenDRIVE lane ``lane_id`` of ``road_id`` at road ``s``
        (None when that lane was not imported)."""
        road = self.odr.roads.get(road_id) or self.odr.road(road_id)
        return self._lanes.get((road.id, lane_id, road.section_at(s)))

    def lanes(self) -> list[SumoLane]:
        """Every SUMO lane that carries an OpenDRIVE lane."""
        return list(self._lanes.values())

    def connects(self, edge: str, next_edge: str) -> bool:
        """Whether SUMO's net leads from the end of ``edge`` straight onto ``next_edge``
        (through a junction or on to the road's next lane section)."""
        return next_edge in self._next.get(edge, ())

    def route_from(self, edge: str, max_edges: int = 64) -> list[str]:
        """Edges a vehicle can follow from ``edge``: the next lane section of the same road
        where there is one, else the first connected edge (SUMO's connection order)."""
        route = [edge]
        while len(route) < max_edges:
            nxt = self._next.get(route[-1], [])
            if not nxt:
                break
            base = route[-1].split("#")[0]
            pick = next((e for e in nxt if e.split("#")[0] == base), nxt[0])
            if pick in route:
                break
            route.append(pick)
        return route

    def origin_of(self, sumo_lane_id: str) -> tuple[str, int, int] | None:
        """(road id, lane id, lane section index) of a SUMO lane, None for lanes without one."""
        return self._by_id.get(sumo_lane_id)

    def place(self, road_id: str, lane_id: int, s: float, offset: float = 0.0) -> Placement:
        """Resolve one OpenDRIVE lane position on the map and on the SUMO net."""
        road = self.odr.road(road_id)
        if not 0.0 <= s <= road.length + 1e-6:
            raise HiyariError(
                f"{self.odr.path}: s = {s:g} m is off road {road.id} (length {road.length:g} m)"
            )
        x, y, z, h = self.odr.lane_pose(road.id, lane_id, np.array([s]), np.array([offset]))
        lane = self.sumo_lane(road.id, lane_id, s)
        return self._placement(
            road, lane_id, float(x[0]), float(y[0]), float(z[0]), float(h[0]), lane
        )

    def place_xy(
        self, x: float, y: float, road_id: str | None = None
    ) -> tuple[RoadCoord, Placement]:
        """Road coordinates of a world point and its placement on the SUMO net."""
        rc = self.odr.locate(np.array([x]), np.array([y]), road_id)[0]
        road = self.odr.road(rc.road)
        z = float(road.z(np.array([rc.s]))[0])
        h = float(road.reference(np.array([rc.s]))[2][0])
        lane = self.sumo_lane(rc.road, rc.lane, rc.s)
        return rc, self._placement(road, rc.lane, x, y, z, h, lane)

    def _placement(
        self,
        road: Road,
        lane_id: int,
        x: float,
        y: float,
        z: float,
        h: float,
        lane: SumoLane | None,
    ) -> Placement:
        heading = h if road.drives_forward(lane_id) else h + math.pi
        heading = math.atan2(math.sin(heading), math.cos(heading))
        if lane is None:
            return Placement(x, y, z, heading, h, "", "", -1, math.nan, math.nan)
        pos, lateral = _on_polyline(lane, x, y)
        return Placement(x, y, z, heading, h, lane.id, lane.edge, lane.index, pos, lateral)


def _on_polyline(lane: SumoLane, x: float, y: float) -> tuple[float, float]:
    """(SUMO position along ``lane``, signed lateral distance to its left) of a point."""
    p0, p1 = lane.shape[:-1], lane.shape[1:]
    seg = p1 - p0
    seg_len2 = np.einsum("ij,ij->i", seg, seg)
    u = np.clip(
        np.einsum("ij,ij->i", np.array([x, y]) - p0, seg) / np.maximum(seg_len2, 1e-18), 0, 1
    )
    foot = p0 + u[:, None] * seg
    d2 = np.sum((foot - [x, y]) ** 2, axis=1)
    k = int(np.argmin(d2))
    along = lane.cum[k] + u[k] * math.sqrt(seg_len2[k])
    cross = seg[k, 0] * (y - p0[k, 1]) - seg[k, 1] * (x - p0[k, 0])
    lateral = math.copysign(math.sqrt(d2[k]), cross)
    return along * lane.length / lane.cum[-1], lateral


def _sumo_lanes(net: Path) -> tuple[dict[tuple[str, int, int], SumoLane], dict[str, list[str]]]:
    """The net's OpenDRIVE-named lanes, and each normal edge's successor edges."""
    root = check_net(net)
    out: dict[tuple[str, int, int], SumoLane] = {}
    normal = {e.get("id") for e in root.iter("edge") if not e.get("function")}
    succ: dict[str, list[str]] = {}
    for c in root.iter("connection"):
        a, b = c.get("from"), c.get("to")
        if a in normal and b in normal and b not in succ.setdefault(a, []):
            succ[a].append(b)
    for e in root.iter("edge"):
        if e.get("function"):
            continue
        eid = e.get("id", "")
        for ln in e.iter("lane"):
            orig = next(
                (p.get("value") for p in ln.iter("param") if p.get("key") == "origId"), None
            )
            if not orig or "_" not in orig:
                continue
            road_id, _, lane_txt = orig.rpartition("_")
            try:
                lane_id = int(lane_txt)
            except ValueError:
                continue
            base, _, sec = eid.lstrip("-").rpartition("#")
            section = int(sec) if base == road_id and sec.isdigit() else 0
            pts = np.array(
                [tuple(map(float, p.split(",")[:2])) for p in ln.get("shape", "").split()]
            )
            if len(pts) < 2:
                continue
            length = ln.get("length")
            out[(road_id, lane_id, section)] = SumoLane.from_shape(
                ln.get("id"),
                eid,
                int(ln.get("index", 0)),
                pts,
                None if length is None else float(length),
            )
    if not out:
        raise HiyariError(
            f"{net}: no lane carries an OpenDRIVE origId (import the map with 'hiyari net import')"
        )
    return out, succ


# ---------------------------------------------------------------------------- reading .xodr
def _f(el: etree._Element, name: str, path: Path, default: float | None = None) -> float:
    text = el.get(name)
    if text is None:
        if default is not None:
            return default
        raise HiyariError(f"{path}:{el.sourceline}: <{el.tag}> lacks attribute {name!r}")
    try:
        return float(text)
    except ValueError:
        raise HiyariError(
            f"{path}:{el.sourceline}: <{el.tag}> {name}={text!r} is not a number"
        ) from None


def _poly(el: etree._Element, path: Path, s_attr: str = "s") -> Poly3:
    return Poly3(*(_f(el, k, path, 0.0) for k in (s_attr, "a", "b", "c", "d")))


def _read_road(path: Path, el: etree._Element) -> Road:
    rid = el.get("id", "")
    length = _f(el, "length", path)
    geoms = tuple(_read_geometry(path, g) for g in el.findall("planView/geometry"))
    offsets = tuple(
        sorted((_poly(o, path) for o in el.findall("lanes/laneOffset")), key=lambda p: p.s0)
    )
    elevation = tuple(
        sorted(
            (_poly(o, path) for o in el.findall("elevationProfile/elevation")), key=lambda p: p.s0
        )
    )
    sec_els = el.findall("lanes/laneSection")
    starts = [_f(s, "s", path) for s in sec_els]
    sections = []
    for k, (sec, s0) in enumerate(zip(sec_els, starts, strict=True)):
        s1 = starts[k + 1] if k + 1 < len(starts) else length
        lanes = {}
        for lane in sec.iter("lane"):
            lid = int(lane.get("id", "0"))
            if lane.find("border") is not None and lane.find("width") is None:
                raise HiyariError(
                    f"{path}:{lane.sourceline}: lane {lid} of road {rid} is defined by <border> records, which hiyari does not read (use <width>)"
                )
            widths = tuple(
                sorted(
                    (_poly(w, path, "sOffset") for w in lane.findall("width")), key=lambda p: p.s0
                )
            )
            lanes[lid] = LaneSpec(lid, lane.get("type", "none"), widths)
        sections.append(LaneSection(k, s0, s1, lanes))
    return Road(
        rid, length, geoms, offsets, tuple(sections), elevation, el.get("rule", "RHT") == "LHT"
    )


def _read_geometry(path: Path, g: etree._Element) -> Geometry:
    s0, x, y, hdg, length = (_f(g, k, path) for k in ("s", "x", "y", "hdg", "length"))
    shape = next(iter(g), None)
    kind = etree.QName(shape).localname if shape is not None else ""
    if kind == "line":
        return Geometry(s0, x, y, hdg, length, "line")
    if kind == "arc":
        return Geometry(s0, x, y, hdg, length, "arc", (_f(shape, "curvature", path),))
    if kind == "spiral":
        k0, k1 = _f(shape, "curvStart", path), _f(shape, "curvEnd", path)
        return Geometry(s0, x, y, hdg, length, "spiral", (k0, k1))
    if kind == "poly3":
        a, b, c, d = (_f(shape, k, path) for k in "abcd")
        return Geometry(
            s0, x, y, hdg, length, "poly3", (a, b, c, d), _poly3_table(a, b, c, d, length)
        )
    if kind == "paramPoly3":
        keys = ("aU", "bU", "cU", "dU", "aV", "bV", "cV", "dV")
        vals = tuple(_f(shape, k, path) for k in keys)
        normalized = shape.get("pRange", "normalized") == "normalized"
        return Geometry(s0, x, y, hdg, length, "paramPoly3", (*vals, float(normalized)))
    raise HiyariError(
        f"{path}:{g.sourceline}: planView geometry <{kind}> is not a known OpenDRIVE shape"
    )


def _poly3_table(
    a: float, b: float, c: float, d: float, length: float
) -> tuple[np.ndarray, np.ndarray]:
    """Arc length along v = a + b u + c u^2 + d u^3 against u, sampled every 1 cm of u."""
    u = np.linspace(0.0, 2.0 * length, max(3, int(2.0 * length / 0.01) + 1))
    dv = b + u * (2 * c + 3 * d * u)
    ds = np.sqrt(1.0 + dv * dv)
    arc = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(u))])
    return arc, u
