"""Safety Cushion Time of vehicle–pedestrian pairs in a WorldState, vehicles along their routes.

Glue between WorldState rows and the metrics in hiyari.risk.metrics.contact: it keeps each
vehicle's route path (registered by the caller, who knows the routes) and turns the current
state into predicted vehicle poses and pedestrian velocities.

Every step's work is batched over all vehicles and pedestrians in the view (a few compiled
passes per step, whatever the number of pairs: pair_kernel, plan_kernel, area_kernel): the
vehicles' paths are sampled from one table of their segments (per-segment values, headings'
cosine and sine included, computed once per route), and the pedestrians' predicted tracks and
whether each track point is on the carriageway are computed once per step and shared by the
metrics and the controller. The values are exactly those of sampling
each vehicle's hiyari.risk.metrics.contact.Path on its own (the same float operations on the
same operands), so batching changes no result.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from hiyari.kinematics import heading_vector
from hiyari.risk.metrics.contact import (
    ContactGeometry,
    Path,
    SCTConfig,
    pedestrian_tracks,
    pedestrian_velocity,
)
from hiyari.risk.metrics.pedestrian_geometry import NetGeometry
from hiyari.risk.sct.area_kernel import AreaTest
from hiyari.risk.sct.contact_kernel import _first_contacts, path_at, project_rows
from hiyari.risk.sct.pair_kernel import crossing_zones, pair_screen
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
        self.times = config.times
        self._paths: dict[str, Path] = {}
        self._route_paths: dict[tuple[str, ...], Path] = {}
        self._segments: dict[int, Segments] = {}  # id(route path) -> its segments
        self._table: tuple[tuple[int, ...], PathTable] | None = None  # the last step's
        self._crossing_index = geometry.crossings.index() if geometry is not None else {}
        road = self.carriageway
        self._road = AreaTest(road) if road is not None and not road.is_empty else None

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
    ) -> StepView:
        """Everything per actor that several metrics of this step share (pedestrian velocity
        predictions and tracks only when ``predict_pedestrians``: SCT and the controller need
        them)."""
        is_ped = state.cls == _PEDESTRIAN
        ped = np.flatnonzero(is_ped)
        lanes = state.lane[ped].tolist()
        if self.geometry is None:
            on_kerb = np.zeros(len(ped), bool)
            kerbs = None
            crossing = np.full(len(ped), -1)
        else:
            g = self.geometry
            on_kerb = np.array([ln in g.footway_lanes for ln in lanes], bool)
            kerbs = g.kerbs
            index = self._crossing_index
            crossing = np.array([index.get(ln, -1) for ln in lanes], int)
        if predict_pedestrians:
            vel, dart = pedestrian_velocity(
                state.xyz[ped, :2],
                state.heading[ped],
                state.speed[ped],
                on_kerb,
                kerbs,
                self.config,
                open_crossings,
            )
            tracks = pedestrian_tracks(
                state.xyz[ped, :2], vel, self.config.speed_factors, self.times
            )
            exposed = self._exposed(tracks)
        else:
            vel, dart = np.full((len(ped), 2), np.nan), np.zeros(len(ped), bool)
            tracks = exposed = None
        veh = np.flatnonzero(~is_ped)
        paths = [self.path_of(state, r) for r in veh.tolist()]
        table = self._path_table(paths)
        s0 = table.project(state.xyz[veh, :2])
        ped_slot = np.full(len(state), -1)
        ped_slot[ped] = np.arange(len(ped))
        veh_slot = np.full(len(state), -1)
        veh_slot[veh] = np.arange(len(veh))
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
            tracks,
            exposed,
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

    def exposed(self, view: StepView, slots: np.ndarray) -> np.ndarray:
        """(n, H, K) bool: the predicted track points of pedestrian slots ``slots`` (n,) that
        lie on the carriageway (all True without one)."""
        return view.exposed[slots]

    def _exposed(self, tracks: np.ndarray) -> np.ndarray:
        """(P, H, K) bool: the track points (P, H, K, 2) on the carriageway (all True without
        one), once per step for every pedestrian of the view."""
        if self._road is None:
            return np.ones(tracks.shape[:3], bool)
        return self._road.contains(tracks)

    def _cv_protected(self, view: StepView, prows: np.ndarray, ped_cv: np.ndarray) -> np.ndarray:
        """(n, K) bool: constant-velocity track points ``ped_cv`` (n, K, 2) of pedestrian rows
        ``prows`` (n,) off the carriageway. A pedestrian without a dart-out prediction walks on at
        its own velocity, so its track is the speed-factor 1 hypothesis: read from
        ``exposed``."""
        road = self.carriageway
        if road is None or road.is_empty:
            return np.zeros(ped_cv.shape[:2], bool)
        factors = list(self.config.speed_factors)
        slots = view.ped_slot[prows]
        if view.tracks is None or 1.0 not in factors:
            reuse = np.zeros(len(prows), bool)
        else:
            reuse = ~view.dart_out[slots]
        out = np.empty(ped_cv.shape[:2], bool)
        if reuse.any():
            out[reuse] = ~self.exposed(view, slots[reuse])[:, factors.index(1.0)]
        if not reuse.all():
            pts = ped_cv[~reuse]
            out[~reuse] = ~self._road.contains(pts)
        return out

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
        n = len(vi)
        if n == 0:
            return np.zeros(0), np.zeros(0), np.zeros(0)
        ttc_contact = ttc_contact or ContactGeometry()
        state, table, t = view.state, view.table, self.times
        seg = table.seg
        prows, pinv = _distinct(pj, len(state))
        vslot = view.veh_slot[vi]
        # shapes per vehicle of the view: half sizes and the near-test reach, for both shapes
        length, width = state.length[view.veh_rows], state.width[view.veh_rows]
        ttc_x, ttc_y, ttc_reach2 = _grown(length, width, ttc_contact)
        contact = self.config.contact
        sct_x, sct_y, sct_reach2 = _grown(length, width, contact)
        slot = view.ped_slot[pj]
        xy, vcos, vsin, ped_cv, gap, near, near_sct = pair_screen(
            state.speed[view.veh_rows],
            view.s0,
            table.cum,
            table.count,
            table.first,
            seg.start,
            seg.unit,
            seg.cum_start,
            seg.cos,
            seg.sin,
            t,
            np.ascontiguousarray(state.xyz[prows, :2]),
            heading_vector(state.heading[prows]),
            state.speed[prows],
            vslot,
            pinv,
            ttc_x,
            ttc_y,
            ttc_contact.pedestrian_radius,
            ttc_reach2,
            view.tracks if with_sct else _NO_TRACKS,
            slot,
            sct_reach2,
        )
        if self._road is not None:
            now = state.xyz[prows, :2]
            on_road = self._road.contains(now)[pinv]
            gap = np.where(on_road, gap, np.inf)
        ttc = np.full(n, np.inf)
        c = np.flatnonzero(near)
        if len(c):
            tracks = ped_cv[pinv[c]]
            ttc[c], _ = _first_contacts(
                xy,
                vcos,
                vsin,
                ttc_x,
                ttc_y,
                ttc_contact.pedestrian_radius,
                tracks,
                ~self._cv_protected(view, pj[c], tracks),
                vslot[c],
                np.arange(len(c)),
                t,
            )
        sct = np.full(n, np.inf)
        if not with_sct:
            return ttc, sct, gap
        c = np.flatnonzero(near_sct)
        if len(c):
            h = view.tracks.shape[1]
            first, _ = _first_contacts(
                xy,
                vcos,
                vsin,
                sct_x,
                sct_y,
                contact.pedestrian_radius,
                view.tracks[slot[c]].reshape(len(c) * h, len(t), 2),
                self.exposed(view, slot[c]).reshape(len(c) * h, len(t)),
                np.repeat(vslot[c], h),
                np.arange(len(c) * h),
                t,
            )
            sct[c] = first.reshape(len(c), h).min(axis=-1)
        return ttc, sct, gap

    def crossing_occupancy(
        self, view: StepView, vi: np.ndarray, pj: np.ndarray, ped_radius: float = 0.3
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For pairs (``vi``, ``pj``): (pedestrian on a crossing the vehicle's path crosses,
        vehicle in their conflict zone, pedestrian in it), each (len(vi),) bool; see
        hiyari.risk.metrics.contact.crossing_conflict."""
        n = len(vi)
        has, vin, pin = np.zeros(n, bool), np.zeros(n, bool), np.zeros(n, bool)
        if self.geometry is None or n == 0:
            return has, vin, pin
        state, seg = view.state, view.table.seg
        cr = self.geometry.crossings
        k = view.crossing[view.ped_slot[pj]]
        on = np.flatnonzero(k >= 0)
        if len(on) == 0:
            return has, vin, pin
        r, kk = vi[on], k[on]
        slot = view.veh_slot[r]
        has[on], vin[on], pin[on] = crossing_zones(
            slot,
            view.s0[slot],
            state.length[r],
            state.width[r],
            view.table.count,
            view.table.first,
            seg.start,
            seg.vector,
            seg.cum_start,
            np.ascontiguousarray(state.xyz[pj[on], :2]),
            cr.direction[kk],
            cr.centre[kk],
            cr.half_length[kk],
            float(ped_radius),
        )
        return has, vin, pin


_NO_TRACKS = np.zeros((0, 1, 1, 2))  # pair_screen's tracks when SCT is not computed


def _grown(
    length: np.ndarray, width: np.ndarray, contact: ContactGeometry
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Half length and width (m) of vehicle rectangles grown by the contact margin, and the
    squared reach of the near test (circumscribed circle, disc and slack), as contact_gap and
    pair_kernel compute them."""
    half_x = 0.5 * length + contact.vehicle_margin
    half_y = 0.5 * width + contact.vehicle_margin
    reach = np.hypot(half_x, half_y) + contact.pedestrian_radius + 1e-6
    return half_x, half_y, reach * reach


def _distinct(rows: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """np.unique(rows, return_inverse=True) for row indices below ``n``, without sorting."""
    used = np.zeros(n, bool)
    used[rows] = True
    distinct = np.flatnonzero(used)
    index = np.empty(n, int)
    index[distinct] = np.arange(len(distinct))
    return distinct, index[rows]


@dataclass
class StepView:
    """Per-step shared values: vehicle rows with their paths, path table and arc lengths (m),
    pedestrian rows with predicted velocities (m/s), dart-out flags, crossing index (-1: not
    on a crossing), predicted tracks (P, H, K, 2) m and whether each track point is on the
    carriageway (P, H, K) (both None when not predicted); ``*_slot`` map a state row to its
    index in these lists."""

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
