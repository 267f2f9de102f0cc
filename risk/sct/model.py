"""Safety Cushion Time of vehicle–pedestrian pairs in a WorldState, vehicles along their routes.

Glue between WorldState rows and the metrics in hiyari.risk.metrics.contact: it keeps each
vehicle's route path (registered by the caller, who knows the routes) and turns the current
state into predicted vehicle poses and pedestrian velocities.
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
    contact_gap,
    crossing_conflict,
    first_contact_time,
    pedestrian_velocity,
    safety_cushion_time,
    unprotected,
)
from hiyari.risk.metrics.pedestrian_geometry import NetGeometry
from hiyari.traffic.world_state import WorldState


class SCTModel:
    """SCT per pair with the dart-out hypothesis; geometry None: straight paths, no dart-out."""

    def __init__(self, geometry: NetGeometry | None, config: SCTConfig | None = None) -> None:
        self.geometry = geometry
        self.config = config = config or SCTConfig()
        self.times = config.times
        self._paths: dict[str, Path] = {}
        self._route_paths: dict[tuple[str, ...], Path] = {}

    def set_route(self, vehicle: str, edges: tuple[str, ...]) -> None:
        """Register the route (edge ids) ``vehicle`` follows; its path is built from the net."""
        if self.geometry is not None:
            route = tuple(edges)
            path = self._route_paths.get(route)
            if path is None:
                path = self._route_paths[route] = Path.of(self.geometry.path(route))
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

    def prepare(
        self,
        state: WorldState,
        open_crossings: np.ndarray | None = None,
        predict_pedestrians: bool = True,
    ) -> StepView:
        """Everything per actor that several metrics of this step share (pedestrian velocity
        predictions only when ``predict_pedestrians``: SCT and the controller need them)."""
        ped = np.flatnonzero(state.is_pedestrian)
        lanes = state.lane[ped].tolist()
        if self.geometry is None:
            on_kerb = np.zeros(len(ped), bool)
            kerbs = None
            crossing = np.full(len(ped), -1)
        else:
            g = self.geometry
            on_kerb = np.array([ln in g.footway_lanes for ln in lanes], bool)
            kerbs = g.kerbs
            index = g.crossings.index()
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
        else:
            vel, dart = np.full((len(ped), 2), np.nan), np.zeros(len(ped), bool)
        veh = np.flatnonzero(state.is_vehicle)
        paths = [self.path_of(state, int(r)) for r in veh]
        s0 = np.array([p.project(state.xyz[r, :2]) for p, r in zip(paths, veh, strict=True)])
        ped_slot = np.full(len(state), -1)
        ped_slot[ped] = np.arange(len(ped))
        veh_slot = np.full(len(state), -1)
        veh_slot[veh] = np.arange(len(veh))
        return StepView(state, veh, paths, s0, veh_slot, ped, vel, dart, crossing, ped_slot)

    def vehicle_poses(
        self, view: StepView, row: int, travel: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Predicted rectangle centres (..., K, 2) and headings (..., K) of vehicle ``row``.

        ``travel`` (..., K): arc length travelled (m) at each sample time; None: the current
        speed held.
        """
        k = view.veh_slot[row]
        if travel is None:
            travel = view.state.speed[row] * self.times
        return view.paths[k].at(view.s0[k] + travel)

    @property
    def carriageway(self) -> shapely.Geometry | None:
        """Where pedestrians are exposed (NetGeometry.carriageway), or None: everywhere."""
        return self.geometry.carriageway if self.geometry is not None else None

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
        (margin, dart-out and speed hypotheses). Pedestrians off the carriageway are protected
        in both. The gap is the TTC shapes' distance now (<= 0: touching).
        ``with_sct`` False: SCT is not computed (inf).
        """
        if len(vi) == 0:
            return np.zeros(0), np.zeros(0), np.zeros(0)
        ttc_contact = ttc_contact or ContactGeometry()
        state = view.state
        vrows, vinv = np.unique(vi, return_inverse=True)
        poses = [self.vehicle_poses(view, int(r)) for r in vrows]
        vxy = np.stack([p[0] for p in poses])[vinv]
        vh = np.stack([p[1] for p in poses])[vinv]
        slot = view.ped_slot[pj]
        length, width = state.length[vi], state.width[vi]
        ped_xy = state.xyz[pj, :2]
        t = self.times
        speed = state.speed[pj, None]
        heading = state.heading[pj]
        cv = heading_vector(heading) * speed
        ped_cv = ped_xy[:, None, :] + cv[:, None, :] * t[None, :, None]
        gap = contact_gap(vxy, vh, length[:, None], width[:, None], ped_cv, ttc_contact)
        gap = unprotected(gap, ped_cv, self.carriageway)
        ttc = first_contact_time(gap, t)
        if not with_sct:
            return ttc, np.full(len(vi), np.inf), gap[:, 0]
        sct = safety_cushion_time(
            vxy, vh, length, width, ped_xy, view.ped_velocity[slot], self.config, self.carriageway
        )
        return ttc, sct, gap[:, 0]

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
        state = view.state
        cr = self.geometry.crossings
        k = view.crossing[view.ped_slot[pj]]
        on = np.flatnonzero(k >= 0)
        for r in np.unique(vi[on]).tolist():
            sel = on[vi[on] == r]
            slot = view.veh_slot[r]
            kk = k[sel]
            h, v, p = crossing_conflict(
                view.paths[slot],
                float(view.s0[slot]),
                float(state.length[r]),
                float(state.width[r]),
                state.xyz[pj[sel], :2],
                cr.direction[kk],
                cr.centre[kk],
                cr.half_length[kk],
                ped_radius,
            )
            has[sel], vin[sel], pin[sel] = h, v, p
        return has, vin, pin


@dataclass
class StepView:
    """Per-step shared values: vehicle rows with their paths and arc lengths (m), pedestrian
    rows with predicted velocities (m/s), dart-out flags and crossing index (-1: not on a
    crossing); ``*_slot`` map a state row to its index in these lists."""

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
