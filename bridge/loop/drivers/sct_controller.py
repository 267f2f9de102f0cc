"""The Safety Cushion Time driver model: careful drivers that keep time to contact with pedestrians.

Each vehicle in scope (a share of all vehicles, the penetration rate) is re-planned every step:
it predicts the pedestrians (constant velocity, or the dart-out hypothesis at the kerb) and
itself along its route under a set of candidate acceleration profiles, and drives the mildest
profile that keeps the Safety Cushion Time at or above ``sct_safe``; when none can, the one
with the largest SCT. Where its own driver (SUMO's) already keeps SCT, it does not intervene.

Profiles (docs/models.md §2; the shapes are the toolkit's choice, since the seed's fitted taxi-driver
polynomials are not published): a cubic ramp a(t) = aT - (aT - a0) (1 - t / T)^3 from the
current acceleration a0 to a target aT, then held; T is the shortest ramp whose jerk (largest
at the start, 3 |aT - a0| / T) stays within the jerk limit. Targets span -0.4 g .. +0.15 g.
Commands go to SUMO as the speed of the next step (``vehicle.setSpeed``) with SUMO's safety
checks left on, so a controlled vehicle is never less careful than SUMO's own driver.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import numpy as np

from hiyari.errors import HiyariError
from hiyari.risk.sct.contact_kernel import travel_rows, within_reach_rows
from hiyari.risk.sct.model import SCTModel, StepView
from hiyari.risk.sct.plan_kernel import decide_rows
from hiyari.traffic.commands import Commands
from hiyari.units import G


@dataclass(frozen=True)
class SCTControllerConfig:
    """SCT driver model parameters.

    sct_safe: s, the Safety Cushion Time the driver keeps to every pedestrian.
    targets_g: target accelerations of the candidate profiles, in g (docs/models.md: -0.4 .. +0.15).
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


def travel(
    accel: np.ndarray,
    v0: float | np.ndarray,
    v_max: float | np.ndarray,
    dt: float,
    stop_speed: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Speeds (..., C, K) m/s and distance travelled (..., C, K) m of acceleration profiles
    (..., C, K) sampled every ``dt`` s from speed ``v0``; speeds are kept within 0 ..
    ``v_max`` (``v0`` and ``v_max`` broadcast against the profiles' leading axes: (..., 1, 1)
    per vehicle). A stopped vehicle stays stopped while the profile brakes. A profile that ends
    braking comes to a full stop once it is slower than ``stop_speed`` m/s. Compiled
    (contact_kernel.travel_rows): one pass per profile."""
    lead = accel.shape[:-1]

    def per_profile(x: float | np.ndarray) -> np.ndarray:
        x = np.asarray(x, float)
        return np.ascontiguousarray(np.broadcast_to(x[..., 0] if x.ndim else x, lead)).ravel()

    v, s = travel_rows(
        np.ascontiguousarray(accel, float).reshape(-1, accel.shape[-1]),
        per_profile(v0),
        per_profile(v_max),
        float(dt),
        float(stop_speed),
    )
    return v.reshape(accel.shape), s.reshape(accel.shape)


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
        # per-model constants of every step's planning: crossings, horizons, hypotheses
        areas = model.geometry.crossings if model.geometry is not None else None
        if areas is None or len(areas) == 0:
            self._areas = (np.zeros(0), np.zeros((0, 2)), np.zeros((0, 4, 2)))
        else:
            reach = np.hypot(areas.half_length, areas.half_width)
            self._areas = (reach, areas.centre, areas.corners)
        times = model.times
        self._upto = min(int(np.searchsorted(times, config.sct_safe)) + 1, len(times))
        self._fastest = max(model.config.speed_factors)
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
        self,
        view: StepView,
        rows: np.ndarray,
        v_max: np.ndarray,
        a_free: np.ndarray,
        engaged: np.ndarray,
    ) -> np.ndarray:
        """(V,) speeds (m/s) to command for the next step to vehicle rows ``rows`` (V,) of
        ``view.state``, NaN where the vehicle is left to its own driver. Per vehicle: ``v_max``
        m/s its allowed speed, ``a_free`` m/s^2 its own driver's maximum acceleration,
        ``engaged`` whether the SCT driver had it on the previous step.

        The SCT driver takes over when even full acceleration by the vehicle's own driver
        would bring SCT below sct_safe, and hands back only once that predicts no contact at
        all within the horizon: in between, handing back would let the own driver speed up
        towards the pedestrian and the two drivers would alternate. All vehicles and
        pedestrians are planned together (one compiled pass, plan_kernel.decide_speeds); each
        vehicle's plan depends only on its own pedestrians, as if planned alone.
        """
        cfg, model = self.config, self.model
        state = view.state
        if len(rows) == 0 or len(view.ped_rows) == 0:
            return np.full(len(rows), np.nan)
        table, seg = view.table, view.table.seg
        contact = model.contact
        # one layout whatever made the state (SUMO's read gives strided columns, a subset or a
        # hand-made state contiguous ones): each layout is a compile of its own, about 30 s
        return decide_rows(
            rows,
            state.speed,
            state.accel,
            np.ascontiguousarray(state.length),
            np.ascontiguousarray(state.width),
            state.xyz,
            np.asarray(v_max, float),
            np.asarray(a_free, float),
            engaged,
            view.veh_slot,
            view.ped_rows,
            contact.vehicle_margin,
            contact.pedestrian_radius,
            view.s0,
            table.cum,
            table.count,
            table.first,
            seg.start,
            seg.unit,
            seg.cum_start,
            seg.cos,
            seg.sin,
            view.tracks,
            view.exposed,
            model.times,
            cfg.act_distance**2,
            self._upto,
            cfg.sct_safe,
            self._targets,
            self._order,
            cfg.jerk_limit,
            cfg.stop_speed,
            *self._areas,
        )

    def step(self, sim: Commands, view: StepView, present: set[str] | None = None) -> None:
        """Plan and command every in-scope vehicle of ``view``; vehicles controlled before but
        not now are handed back to their own driver. ``present``: ids of all vehicles in the
        simulation (default: those in the view)."""
        state, cfg = view.state, self.config
        decided: set[str] = set()
        if len(view.ped_rows):
            reach = self._within_reach(view).tolist()
            rows, ids, v_max, a_free = [], [], [], []
            for k, r in enumerate(view.veh_rows.tolist()):
                vid = state.ids[r]
                if not (reach[k] or vid in self.controlled) or not self.in_scope(vid):
                    continue
                if state.speed[r] < cfg.stop_speed and _held_by_signal(sim, vid):
                    continue  # SUMO keeps it standing at a red light anyway
                a = self._accel.get(vid)
                if a is None:
                    a = self._accel[vid] = sim.max_accel(vid)
                rows.append(r)
                ids.append(vid)
                v_max.append(sim.allowed_speed(vid))
                a_free.append(a)
            engaged = np.array([vid in self.controlled for vid in ids], bool)
            cmd = self.decide(view, np.array(rows, int), np.array(v_max), np.array(a_free), engaged)
            for vid, c in zip(ids, cmd.tolist(), strict=True):
                if not math.isnan(c):
                    sim.set_speed(vid, c)
                    decided.add(vid)
                    self.interventions += 1
        if present is None:
            present = set(state.ids[view.veh_rows].tolist())
        for vid in sorted(self.controlled - decided):  # a set: fix the order of commands
            if vid in present:
                sim.release_speed(vid)  # back to its own driver
        self.controlled = decided

    def _within_reach(self, view: StepView) -> np.ndarray:
        """(V,) bool: vehicles that could touch some pedestrian hypothesis within sct_safe.

        A bound, so the others need no planning: the vehicle at most accelerates at
        ``max_accel`` from its speed, the pedestrian moves at most at the fastest hypothesis.
        """
        cfg, state, sc = self.config, view.state, self.model.config
        t = cfg.sct_safe
        return within_reach_rows(
            state.xyz,
            state.length,
            state.width,
            state.speed,
            view.veh_rows,
            view.ped_rows,
            view.ped_velocity,
            sc.vehicle_margin,
            sc.pedestrian_radius,
            self._fastest,
            t,
            0.5 * cfg.max_accel * t * t,
        )

    def release_all(self, sim: Commands, present: set[str]) -> None:
        """Hand every controlled vehicle still in the simulation back to its own driver."""
        for vid in sorted(self.controlled & present):
            sim.release_speed(vid)
        self.controlled = set()


def _held_by_signal(sim: Commands, vehicle: str, distance: float = 15.0) -> bool:
    """True when the next traffic light of ``vehicle``, within ``distance`` m, shows red or
    yellow to it."""
    nxt = sim.next_signal(vehicle)
    return nxt is not None and nxt.distance <= distance and nxt.state in "rRyYu"
