"""The Safety Cushion Time driver model: careful drivers that keep time to contact with pedestrians.

Each vehicle in scope (a share of all vehicles, the penetration rate) is re-planned every step:
it predicts the pedestrians (constant velocity, or the dart-out hypothesis at the kerb) and
itself along its route under a set of candidate acceleration profiles, and drives the mildest
profile that keeps the Safety Cushion Time at or above ``sct_safe``; when none can, the one
with the largest SCT. Where its own driver (SUMO's) already keeps SCT, it does not intervene.

Profiles (MODELS.md §2; the shapes are the toolkit's choice, since the seed's fitted taxi-driver
polynomials are not published): a cubic ramp a(t) = aT - (aT - a0) (1 - t / T)^3 from the
current acceleration a0 to a target aT, then held; T is the shortest ramp whose jerk (largest
at the start, 3 |aT - a0| / T) stays within the jerk limit. Targets span -0.4 g .. +0.15 g.
Commands go to SUMO as the speed of the next step (``vehicle.setSpeed``) with SUMO's safety
checks left on, so a controlled vehicle is never less careful than SUMO's own driver.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass

import numpy as np
import shapely

from hiyari.errors import HiyariError
from hiyari.kinematics import footprint_corners, overlap_depth
from hiyari.risk.metrics.contact import contact_gap, first_contact_time, pedestrian_tracks
from hiyari.risk.sct.model import SCTModel, StepView
from hiyari.traffic.commands import Commands
from hiyari.traffic.world_state import WorldState
from hiyari.units import G


@dataclass(frozen=True)
class SCTControllerConfig:
    """SCT driver model parameters.

    sct_safe: s, the Safety Cushion Time the driver keeps to every pedestrian.
    targets_g: target accelerations of the candidate profiles, in g (MODELS.md: -0.4 .. +0.15).
    jerk_limit: m/s^3, bound on the ramp's peak jerk.
    act_distance: m, the driver acts only where a pedestrian is this close to its predicted
        path (its positions over the horizon at the current speed).
    penetration: share of vehicles (0..1) driven by the SCT model; the others keep SUMO's.
    stop_speed: m/s, a braking profile that gets slower than this stops: careful drivers stop
        and wait rather than crawl towards a pedestrian (and SUMO's pedestrians cross in front
        of a stopped car, not of a crawling one).
    max_accel: m/s^2, bound on any vehicle's acceleration, used to skip planning for vehicles
        that cannot reach a pedestrian within sct_safe.
    """

    sct_safe: float = 4.0
    targets_g: tuple[float, ...] = (
        -0.4,
        -0.35,
        -0.3,
        -0.25,
        -0.2,
        -0.15,
        -0.1,
        -0.05,
        0.0,
        0.05,
        0.1,
        0.15,
    )
    jerk_limit: float = 3.0
    act_distance: float = 30.0
    penetration: float = 1.0
    stop_speed: float = 1.0
    max_accel: float = 3.0

    def validate(self) -> None:
        """Raise HiyariError for impossible parameters."""
        if not 0.0 <= self.penetration <= 1.0:
            raise HiyariError(f"SCT penetration must be in 0..1, got {self.penetration}")
        if self.sct_safe <= 0 or self.jerk_limit <= 0 or self.act_distance <= 0:
            raise HiyariError("SCT controller: sct_safe, jerk_limit and act_distance must be > 0")
        if not self.targets_g:
            raise HiyariError("SCT controller: targets_g needs at least one acceleration")


def ramp_profiles(
    a0: float, targets: np.ndarray, times: np.ndarray, jerk_limit: float
) -> np.ndarray:
    """(C, K) acceleration, m/s^2, of cubic ramps from ``a0`` to each target at ``times`` s:
    a(t) = aT - (aT - a0) (1 - t / T)^3 up to T, then aT. The jerk is largest at the start,
    3 |aT - a0| / T, and T is chosen to make that the jerk limit; it fades to 0 at the
    plateau. (Re-planned every step, a ramp that started with zero jerk would never leave a0.)"""
    delta = targets - a0
    ramp = np.maximum(3.0 * np.abs(delta) / jerk_limit, 1e-6)
    tau = np.minimum(times[None, :] / ramp[:, None], 1.0)
    return targets[:, None] - delta[:, None] * (1.0 - tau) ** 3


def travel(
    accel: np.ndarray, v0: float, v_max: float, dt: float, stop_speed: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Speeds (C, K) m/s and distance travelled (C, K) m of acceleration profiles (C, K) sampled
    every ``dt`` s from speed ``v0``; speeds are kept within 0 .. ``v_max`` (a stopped vehicle
    stays stopped while the profile brakes). A profile that ends braking comes to a full stop
    once it is slower than ``stop_speed`` m/s."""
    dv = 0.5 * (accel[:, 1:] + accel[:, :-1]) * dt
    v = np.clip(v0 + np.concatenate([np.zeros((len(accel), 1)), np.cumsum(dv, 1)], 1), 0, v_max)
    if stop_speed > 0:
        slow = (v < stop_speed) & (accel[:, -1:] <= 0)
        v = np.where(np.logical_or.accumulate(slow, axis=1), 0.0, v)
    ds = 0.5 * (v[:, 1:] + v[:, :-1]) * dt
    return v, np.concatenate([np.zeros((len(accel), 1)), np.cumsum(ds, 1)], 1)


class SCTController:
    """Applies the SCT driver model through libsumo to the vehicles in its scope."""

    def __init__(
        self, model: SCTModel, config: SCTControllerConfig = SCTControllerConfig(), seed: int = 0
    ) -> None:
        config.validate()
        self.model = model
        self.config = config
        self.seed = seed
        self._targets = np.asarray(config.targets_g, float) * G
        self._order = np.argsort(-self._targets, kind="stable")  # mildest (least braking) first
        self._scope: dict[str, bool] = {}
        self._accel: dict[str, float] = {}
        self.controlled: set[str] = set()
        self.interventions = 0  # vehicle-steps with a command

    def in_scope(self, vehicle: str) -> bool:
        """Whether ``vehicle`` is an SCT vehicle: a seeded draw per id against the penetration
        rate (the same ids stay in scope as the rate grows)."""
        hit = self._scope.get(vehicle)
        if hit is None:
            u = np.random.default_rng([self.seed, zlib.crc32(vehicle.encode())]).random()
            hit = self._scope[vehicle] = bool(u < self.config.penetration)
        return hit

    def decide(
        self, view: StepView, row: int, v_max: float, a_free: float, engaged: bool = False
    ) -> float | None:
        """Speed (m/s) to command for the next step for vehicle ``row`` of ``view.state``, or
        None to leave it to its own driver. ``v_max`` m/s: its allowed speed; ``a_free``
        m/s^2: its own driver's maximum acceleration; ``engaged``: the SCT driver had it on
        the previous step.

        The SCT driver takes over when even full acceleration by the vehicle's own driver
        would bring SCT below sct_safe, and hands back only once that predicts no contact at
        all within the horizon: in between, handing back would let the own driver speed up
        towards the pedestrian and the two drivers would alternate.
        """
        cfg, model = self.config, self.model
        state = view.state
        times = model.times
        dt = float(times[1] - times[0])
        v0, a0 = float(state.speed[row]), float(state.accel[row])
        v_max = max(v_max, v0)
        # the vehicle's own driver at its most demanding: full acceleration to its allowed speed
        _, s_free = travel(np.full((1, len(times)), a_free), v0, v_max, dt)
        xy, hd = model.vehicle_poses(view, row, s_free)
        now = state.xyz[view.ped_rows, :2]
        d = now[:, None, :] - xy[0, ::5][None]
        keep = np.einsum("pkj,pkj->pk", d, d).min(axis=1) <= cfg.act_distance**2
        if not keep.any():
            return None
        slots = np.flatnonzero(keep)
        # every pedestrian speed hypothesis as its own track: (P * H, K, 2)
        ped = pedestrian_tracks(
            now[slots], view.ped_velocity[slots], model.config.speed_factors, times
        )
        ped = ped.reshape(-1, len(times), 2)
        # pedestrians off the carriageway are protected (SUMO's corner geometry)
        road = model.carriageway
        protected = (
            ~shapely.contains_xy(road, ped[..., 0], ped[..., 1])
            if road is not None and not road.is_empty
            else np.zeros(ped.shape[:2], bool)
        )
        length, width = state.length[row], state.width[row]
        contact = model.config.contact
        gap = contact_gap(xy[:, None], hd[:, None], length, width, ped[None], contact)
        gap = np.where(protected[None], np.inf, gap)
        # pedestrians already touching the vehicle cannot be helped by any profile
        apart = gap[0, :, 0] > 0
        if not apart.any():
            return None
        sct_free = first_contact_time(gap[:, apart], times).min()
        if np.isinf(sct_free) or (sct_free >= cfg.sct_safe and not engaged):
            return None
        accel = ramp_profiles(a0, self._targets, times, cfg.jerk_limit)
        v, s = travel(accel, v0, v_max, dt, cfg.stop_speed)
        xy, hd = model.vehicle_poses(view, row, s)
        gap = contact_gap(xy[:, None], hd[:, None], length, width, ped[apart][None], contact)
        gap = np.where(protected[apart][None], np.inf, gap)
        sct = first_contact_time(gap, times).min(axis=1)  # (C,)
        blocks = self._stops_on_crossing(xy[:, -1], hd[:, -1], v[:, -1], state, row)
        if not blocks.all():  # keep crossings clear: never plan to stop on one
            sct = np.where(blocks, -1.0, sct)
        ordered = sct[self._order]
        # once the cushion is threatened: no contact within the horizon if possible (a plan that
        # merely postpones contact beyond sct_safe creeps towards a waiting pedestrian step by
        # step), else a cushion of at least sct_safe, else the largest cushion
        clear = np.flatnonzero(np.isinf(ordered))
        ok = clear if len(clear) else np.flatnonzero(ordered >= cfg.sct_safe)
        if len(ok):
            pick = self._order[ok[0]]
        else:
            best = np.flatnonzero(sct == sct.max())
            pick = best[np.argmin(self._targets[best])]  # equal SCT: brake hardest
        return float(v[pick, 1])

    def _stops_on_crossing(
        self, xy: np.ndarray, heading: np.ndarray, v_end: np.ndarray, state: WorldState, row: int
    ) -> np.ndarray:
        """(C,) bool: candidates that end stopped with the vehicle over a crossing."""
        areas = self.model.geometry.crossings if self.model.geometry is not None else None
        stopped = v_end <= 0.0
        if areas is None or len(areas) == 0 or not stopped.any():
            return np.zeros(len(xy), bool)
        rect = footprint_corners(xy, heading, state.length[row], state.width[row])
        n, a = len(rect), len(areas)
        depth = overlap_depth(np.repeat(rect, a, 0), np.tile(areas.corners, (n, 1, 1)))
        return stopped & (depth.reshape(n, a) > 0).any(axis=1)

    def step(self, sim: Commands, view: StepView, present: set[str] | None = None) -> None:
        """Plan and command every in-scope vehicle of ``view``; vehicles controlled before but
        not now are handed back to their own driver. ``present``: ids of all vehicles in the
        simulation (default: those in the view)."""
        state, cfg = view.state, self.config
        decided: set[str] = set()
        if len(view.ped_rows):
            reach = self._within_reach(view)
            for k, r in enumerate(view.veh_rows.tolist()):
                vid = state.ids[r]
                if not (reach[k] or vid in self.controlled) or not self.in_scope(vid):
                    continue
                if state.speed[r] < cfg.stop_speed and _held_by_signal(sim, vid):
                    continue  # SUMO keeps it standing at a red light anyway
                v_max = sim.allowed_speed(vid)
                a_free = self._accel.get(vid)
                if a_free is None:
                    a_free = self._accel[vid] = sim.max_accel(vid)
                cmd = self.decide(view, r, v_max, a_free, vid in self.controlled)
                if cmd is not None:
                    sim.set_speed(vid, cmd)
                    decided.add(vid)
                    self.interventions += 1
        if present is None:
            present = set(state.ids[view.veh_rows].tolist())
        for vid in self.controlled - decided:
            if vid in present:
                sim.release_speed(vid)  # back to its own driver
        self.controlled = decided

    def _within_reach(self, view: StepView) -> np.ndarray:
        """(V,) bool: vehicles that could touch some pedestrian hypothesis within sct_safe.

        A bound, so the others need no planning: the vehicle at most accelerates at
        ``max_accel`` from its speed, the pedestrian moves at most at the fastest hypothesis.
        """
        cfg, state = self.config, view.state
        v, p = view.veh_rows, view.ped_rows
        d = np.linalg.norm(state.xyz[v, None, :2] - state.xyz[None, p, :2], axis=2)
        sc = self.model.config
        reach = 0.5 * np.hypot(state.length[v], state.width[v]) + sc.vehicle_margin
        gap = d - reach[:, None] - sc.pedestrian_radius
        ped_speed = np.linalg.norm(view.ped_velocity, axis=1) * max(sc.speed_factors)
        t = cfg.sct_safe
        travel = (state.speed[v, None] + ped_speed[None]) * t + 0.5 * cfg.max_accel * t * t
        return (gap <= travel).any(axis=1)

    def release_all(self, sim: Commands, present: set[str]) -> None:
        """Hand every controlled vehicle still in the simulation back to its own driver."""
        for vid in self.controlled & present:
            sim.release_speed(vid)
        self.controlled = set()


def _held_by_signal(sim: Commands, vehicle: str, distance: float = 15.0) -> bool:
    """True when the next traffic light of ``vehicle``, within ``distance`` m, shows red or
    yellow to it."""
    nxt = sim.next_signal(vehicle)
    return nxt is not None and nxt.distance <= distance and nxt.state in "rRyYu"
