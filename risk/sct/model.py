"""Safety Cushion Time of vehicle–pedestrian pairs in a WorldState, vehicles along their routes.

Glue between WorldState rows and the metrics in hiyari.risk.metrics.contact: it keeps each
vehicle's route path (registered by the caller, who knows the routes) and turns the current
state into predicted vehicle poses and pedestrian velocities.

Every step's work is batched over all vehicles and pedestrians in the view (a few compiled
passes per step, whatever the number of pairs: track_kernel, pair_kernel, plan_kernel): the
vehicles' paths are sampled from one table of their segments (per-segment values, headings'
cosine and sine included, computed once per route), and the pedestrians' predicted tracks and
whether each track point is on the carriageway are computed once per step and shared by the
metrics and the controller. The values are exactly those of sampling
each vehicle's hiyari.risk.metrics.contact.Path on its own (the same float operations on the
same operands), so batching changes no result.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from hiyari.risk.metrics.contact import ContactGeometry, Path, SCTConfig
from hiyari.risk.metrics.pedestrian_geometry import KerbSegments, NetGeometry
from hiyari.risk.sct.area_kernel import AreaTest
from hiyari.risk.sct.contact_kernel import path_at, project_rows
from hiyari.risk.sct.pair_kernel import crossing_pairs, pair_pass
from hiyari.risk.sct.track_kernel import ASK_ALL, EVERYWHERE, RINGS, predict_tracks, row_slots
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.world_state import WorldState

_PEDESTRIAN = np.int8(ActorClass.PEDESTRIAN)  # compared as a numpy scalar: no enum lookup


@dataclass(frozen=True)
class Segments:
    """A path's segments with the values Path.project and Path.at derive from them: start
    (S, 2) m, vector (S, 2) m, squared length (S,) m^2 (>= 1e-12), arc length at the start
    (S,) m, unit direction (S, 2) and heading (S,) rad with its cosine and sine (numpy's, as
    first_contacts takes them); ``cum`` (S + 1,) the path's arc lengths."""

    start: np.ndarray
    vector: np.ndarray
    length2: np.ndarray
    cum_start: np.ndarray
    unit: np.ndarray
    heading: np.ndarray
    cum: np.ndarray
    cos: np.ndarray
    sin: np.ndarray

    @staticmethod
    def of(path: Path) -> Segments:
        """The segments of ``path``."""
        start = path.points[:-1]
        vector = path.points[1:] - start
        length2 = np.maximum(np.einsum("ij,ij->i", vector, vector), 1e-12)
        unit = vector / np.maximum(path.cum[1:] - path.cum[:-1], 1e-12)[:, None]
        heading = np.arctan2(unit[:, 1], unit[:, 0])
        return Segments(
            start,
            vector,
            length2,
            path.cum[:-1],
            unit,
            heading,
            path.cum,
            np.cos(heading),
            np.sin(heading),
        )


@dataclass(frozen=True)
class PathTable:
    """The segments of V vehicles' paths in one table; vehicle v owns rows ``first[v]`` ..
    ``first[v] + count[v] - 1``."""

    seg: Segments  # concatenated over the vehicles (``cum`` unused)
    owner: np.ndarray  # (S,) vehicle index of each row
    first: np.ndarray  # (V,)
    count: np.ndarray  # (V,)
    cum: np.ndarray  # (V, M) each path's arc lengths, padded with +inf

    @staticmethod
    def of(parts: list[Segments]) -> PathTable:
        """The table of ``parts`` (one per vehicle)."""
        count = np.array([len(p.start) for p in parts], int)
        first = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(int)
        cum = np.full((len(parts), int(count.max(initial=0)) + 1), np.inf)
        for v, p in enumerate(parts):
            cum[v, : len(p.cum)] = p.cum

        def cat(name: str) -> np.ndarray:
            return np.concatenate([getattr(p, name) for p in parts])

        if not parts:
            empty = np.zeros((0, 2))
            none = np.zeros(0)
            seg = Segments(empty, empty, none, none, empty, none, none, none, none)
        else:
            seg = Segments(
                cat("start"),
                cat("vector"),
                cat("length2"),
                cat("cum_start"),
                cat("unit"),
                cat("heading"),
                np.zeros(0),
                cat("cos"),
                cat("sin"),
            )
        return PathTable(seg, np.repeat(np.arange(len(parts)), count), first, count, cum)

    def project(self, xy: np.ndarray) -> np.ndarray:
        """(V,) arc length (m) of the point of each vehicle's path nearest to ``xy`` (V, 2);
        Path.project of each."""
        s = self.seg
        return project_rows(
            np.ascontiguousarray(xy, float),
            self.first,
            self.count,
            s.start,
            s.vector,
            s.length2,
            s.cum_start,
        )

    def at(self, vehicles: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(xy (..., 2), heading (...)) at arc lengths ``s`` (n, ...) m along the paths of
        ``vehicles`` (n,) (indices into this table); Path.at of each."""
        seg = self.seg
        return path_at(
            self.cum,
            self.count,
            self.first,
            seg.start,
            seg.unit,
            seg.cum_start,
            seg.heading,
            vehicles,
            s,
        )


class SCTModel:
    """SCT per pair with the dart-out hypothesis; geometry None: straight paths, no dart-out."""

    def __init__(self, geometry: NetGeometry | None, config: SCTConfig | None = None) -> None:
        self.geometry = geometry
        self.config = config = config or SCTConfig()
        self.contact = config.contact  # the SCT shapes (the config builds one per access)
        self.times = config.times
        self._paths: dict[str, Path] = {}
        self._route_paths: dict[tuple[str, ...], Path] = {}
        self._segments: dict[int, Segments] = {}  # id(route path) -> its segments
        self._table: tuple[tuple[int, ...], PathTable] | None = None  # the last step's
        self._crossing_index = geometry.crossings.index() if geometry is not None else {}
        road = self.carriageway
        self._road = AreaTest(road) if road is not None and not road.is_empty else None
        # the pedestrians' prediction pass: kerbs, the facing bound, the carriageway's rings
        self._kerbs = geometry.kerbs if geometry is not None else _NO_KERBS
        self._cos_max = math.cos(math.radians(config.dart_out_max_angle_deg))
        self._no_facing = np.zeros((0, len(self._kerbs)), bool)
        self._factors = np.asarray(config.speed_factors, float)
        if self._road is None:
            self._area, self._rings = EVERYWHERE, _NO_RINGS
        elif self._road.rings is None:
            self._area, self._rings = ASK_ALL, _NO_RINGS
        else:
            self._area, self._rings = RINGS, self._road.rings

    def set_route(self, vehicle: str, edges: tuple[str, ...]) -> None:
        """Register the route (edge ids) ``vehicle`` follows; its path is built from the net."""
        if self.geometry is not None:
            route = tuple(edges)
            path = self._route_paths.get(route)
            if path is None:
                path = self._route_paths[route] = Path.of(self.geometry.path(route))
                self._segments[id(path)] = Segments.of(path)
            self._paths[vehicle] = path

    def has_route(self, vehicle: str) -> bool:
        return vehicle in self._paths

    def forget_absent(self, present: set[str]) -> None:
        """Drop the paths of vehicles not in ``present`` (they left the simulation)."""
        for v in [v for v in self._paths if v not in present]:
            del self._paths[v]

    def path_of(self, state: WorldState, row: int) -> Path:
        """The vehicle's route path, or a straight line along its heading if it has none."""
        path = self._paths.get(state.ids[row])
        if path is None:
            path = Path.straight(state.xyz[row, :2], float(state.heading[row]))
        return path

    def _path_table(self, paths: list[Path]) -> PathTable:
        """The table of ``paths``; the last step's when its vehicles follow the same routes."""
        key = tuple(id(p) for p in paths)
        if self._table is not None and self._table[0] == key:
            return self._table[1]
        parts = [self._segments.get(id(p)) for p in paths]
        table = PathTable.of(
            [s if s is not None else Segments.of(p) for s, p in zip(parts, paths, strict=True)]
        )
        if all(s is not None for s in parts):  # route paths live as long as the model
            self._table = (key, table)
        return table

    def prepare(
        self,
        state: WorldState,
        open_crossings: np.ndarray | None = None,
        predict_pedestrians: bool = True,
        rows: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> StepView:
        """Everything per actor that several metrics of this step share (pedestrian velocity
        predictions and tracks only when ``predict_pedestrians``: SCT and the controller need
        them), for the (vehicle rows, pedestrian rows) ``rows`` of ``state`` (default: all)."""
        if rows is None:
            is_ped = state.cls == _PEDESTRIAN
            veh, ped = np.flatnonzero(~is_ped), np.flatnonzero(is_ped)
        else:
            veh, ped = rows
        lanes = state.lane[ped].tolist()
        if self.geometry is None:
            kerb = _NO_ROWS
            crossing = np.full(len(ped), -1)
        else:
            footway = self.geometry.footway_lanes
            kerb = np.array([i for i, ln in enumerate(lanes) if ln in footway], np.int64)
            index = self._crossing_index
            crossing = np.array([index.get(ln, -1) for ln in lanes], int)
        vel, dart, tracks, cv, exposed, cv_exposed = self._predict(
            state, ped, kerb, open_crossings, predict_pedestrians
        )
        paths = [self.path_of(state, r) for r in veh.tolist()]
        table = self._path_table(paths)
        s0 = table.project(state.xyz[veh, :2])
        veh_slot, ped_slot = row_slots(len(state), veh, ped)
        return StepView(
            state,
            veh,
            paths,
            s0,
            veh_slot,
            ped,
            vel,
            dart,
            crossing,
            ped_slot,
            table,
            tracks if predict_pedestrians else None,
            exposed if predict_pedestrians else None,
            cv,
            cv_exposed,
        )

    def vehicle_poses(
        self, view: StepView, rows: np.ndarray, travel: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Predicted rectangle centres (n, ..., K, 2) and headings (n, ..., K) of vehicle rows
        ``rows`` (n,) of ``view.state``.

        ``travel`` (n, ..., K): arc length travelled (m) at each sample time; None: the
        current speeds held.
        """
        slots = view.veh_slot[rows]
        if travel is None:
            travel = view.state.speed[rows][:, None] * self.times
        s0 = view.s0[slots].reshape(len(rows), *([1] * (travel.ndim - 1)))
        return view.table.at(slots, s0 + travel)

    @property
    def carriageway(self) -> shapely.Geometry | None:
        """Where pedestrians are exposed (NetGeometry.carriageway), or None: everywhere."""
        return self.geometry.carriageway if self.geometry is not None else None

    def _predict(
        self,
        state: WorldState,
        ped: np.ndarray,
        kerb: np.ndarray,
        open_crossings: np.ndarray | None,
        predict: bool,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """For the pedestrian rows ``ped`` of ``state`` (``kerb``: indices into ``ped`` of
        those on a footway), in one pass (track_kernel): predicted velocities (P, 2) m/s and
        dart-out flags (P,) (contact.pedestrian_velocity) with their tracks (P, H, K, 2) m
        (contact.pedestrian_tracks) when ``predict`` (else NaN, False and no tracks), the
        constant-velocity tracks (P, K, 2) m, and whether each point of both track sets is on
        the carriageway (all True without one)."""
        u = _unit(state.heading[ped])
        rows = kerb if predict else _NO_ROWS
        kerbs = self._kerbs
        facing = u[rows] @ kerbs.inward.T >= self._cos_max if len(rows) else self._no_facing
        cfg = self.config
        vel, dart, tracks, cv, exposed, cv_exposed, ask = predict_tracks(
            state.xyz,
            state.speed,
            ped,
            u,
            predict,
            rows,
            facing,
            kerbs.a,
            kerbs.b,
            kerbs.inward,
            kerbs.crossing,
            _ALL_OPEN if open_crossings is None else np.asarray(open_crossings, bool),
            self._cos_max,
            float(cfg.dart_out_distance),
            float(cfg.dart_out_speed),
            self._factors,
            self.times,
            self._area,
            *self._rings,
        )
        if len(ask):  # on (or within rounding of) the carriageway's boundary: GEOS decides
            points = np.concatenate([tracks.reshape(-1, 2), cv.reshape(-1, 2)])[ask]
            on = shapely.contains_xy(self._road.area, points[:, 0], points[:, 1])
            n = exposed.size
            exposed.reshape(-1)[ask[ask < n]] = on[ask < n]
            cv_exposed.reshape(-1)[ask[ask >= n] - n] = on[ask >= n]
        return vel, dart, tracks, cv, exposed, cv_exposed

    def pair_metrics(
        self,
        view: StepView,
        vi: np.ndarray,
        pj: np.ndarray,
        ttc_contact: ContactGeometry | None = None,
        with_sct: bool = True,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Time to contact (s), SCT (s) and contact-now gap (m) of pairs (vehicle rows ``vi``,
        pedestrian rows ``pj``); vehicles keep their current speed along their routes.

        TTC: pedestrians at constant velocity, shapes ``ttc_contact`` (default: the vehicle
        rectangle as is, a 0.3 m disc). SCT: this model's config
        (margin, dart-out and speed hypotheses), i.e.
        hiyari.risk.metrics.contact.safety_cushion_time on the step's shared pedestrian
        tracks. Pedestrians off the carriageway are protected in both. The gap is the TTC
        shapes' distance now (<= 0: touching). ``with_sct`` False: SCT is not computed (inf).
        Pairs whose tracks never come near enough to touch (pair_kernel's near test) are inf without
        further work.
        """
        if len(vi) == 0:
            return np.zeros(0), np.zeros(0), np.zeros(0)
        ttc_contact = ttc_contact or ContactGeometry()
        state, table, seg = view.state, view.table, view.table.seg
        veh = view.veh_rows
        contact = self.contact
        return pair_pass(
            state.speed[veh],
            state.length[veh],
            state.width[veh],
            view.s0,
            table.cum,
            table.count,
            table.first,
            seg.start,
            seg.unit,
            seg.cum_start,
            seg.cos,
            seg.sin,
            self.times,
            view.cv_tracks,
            view.cv_exposed,
            self._road is not None,
            view.veh_slot[vi],
            view.ped_slot[pj],
            ttc_contact.vehicle_margin,
            ttc_contact.pedestrian_radius,
            contact.vehicle_margin,
            contact.pedestrian_radius,
            view.tracks if with_sct else _NO_TRACKS,
            view.exposed if with_sct else _NO_EXPOSED,
        )

    def crossing_occupancy(
        self, view: StepView, vi: np.ndarray, pj: np.ndarray, ped_radius: float = 0.3
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For pairs (``vi``, ``pj``): (pedestrian on a crossing the vehicle's path crosses,
        vehicle in their conflict zone, pedestrian in it), each (len(vi),) bool; see
        hiyari.risk.metrics.contact.crossing_conflict."""
        n = len(vi)
        if self.geometry is None or n == 0:
            return np.zeros(n, bool), np.zeros(n, bool), np.zeros(n, bool)
        state, table, seg = view.state, view.table, view.table.seg
        cr = self.geometry.crossings
        return crossing_pairs(
            vi,
            pj,
            view.veh_slot,
            view.ped_slot,
            view.crossing,
            view.s0,
            state.length,
            state.width,
            state.xyz,
            table.count,
            table.first,
            seg.start,
            seg.vector,
            seg.cum_start,
            cr.direction,
            cr.centre,
            cr.half_length,
            float(ped_radius),
        )


_NO_TRACKS = np.zeros((0, 1, 1, 2))  # pair_pass' tracks when SCT is not computed
_NO_EXPOSED = np.zeros((0, 1, 1), bool)
_NO_ROWS = np.zeros(0, np.int64)  # no pedestrian to predict at the kerb
_ALL_OPEN = np.zeros(0, bool)  # predict_tracks' open crossings: no signals, all open
_NO_KERBS = KerbSegments(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0, int))
# predict_tracks' rings when locate_xy is not used
_NO_RINGS = (
    np.zeros((0, 2)),
    np.zeros(0, np.int64),
    np.zeros(0),
    np.zeros(0, np.int64),
    np.zeros(0, np.int64),
)


def _unit(heading: np.ndarray) -> np.ndarray:
    """(N, 2) unit vectors along ``heading`` (N,) rad: kinematics.heading_vector's values
    without np.stack's per-call overhead."""
    u = np.empty((len(heading), 2))
    u[:, 0] = np.cos(heading)
    u[:, 1] = np.sin(heading)
    return u


@dataclass
class StepView:
    """Per-step shared values: vehicle rows with their paths, path table and arc lengths (m),
    pedestrian rows with predicted velocities (m/s), dart-out flags, crossing index (-1: not
    on a crossing), predicted tracks (P, H, K, 2) m and whether each track point is on the
    carriageway (P, H, K) (both None when not predicted), constant-velocity tracks (P, K, 2) m
    (each pedestrian at its own velocity, for time to contact) and whether each of their
    points is on the carriageway (P, K); ``*_slot`` map a state row to its index in these
    lists."""

    state: WorldState
    veh_rows: np.ndarray
    paths: list[Path]
    s0: np.ndarray
    veh_slot: np.ndarray
    ped_rows: np.ndarray
    ped_velocity: np.ndarray
    dart_out: np.ndarray
    crossing: np.ndarray
    ped_slot: np.ndarray
    table: PathTable
    tracks: np.ndarray | None
    exposed: np.ndarray | None
    cv_tracks: np.ndarray
    cv_exposed: np.ndarray
