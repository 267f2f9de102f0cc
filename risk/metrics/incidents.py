"""Vehicle–pedestrian encounters and incidents, logged once per pair (docs/models.md §2).

An encounter is one vehicle–pedestrian pair that came within reach of each other: some
time-to-contact or SCT inside the horizon, a post-encroachment at a crossing, or a contact. It
keeps the pair's minimum TTC, SCT and PET over the whole run, the positions and speeds at its
worst moment, and whether they collided. It is an incident when the minimum TTC is below
``ttc_threshold``, or the minimum PET below ``pet_threshold``, or they collided.
"""

from __future__ import annotations

import csv
import math
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.risk.metrics.contact import (
    ContactGeometry,
    PetEvent,
    contact_gap,
    time_to_contact,
)
from hiyari.traffic.world_state import WorldState


@dataclass(frozen=True)
class IncidentConfig:
    """Incident thresholds and the reach of the pair search.

    ttc_threshold: s, an encounter whose minimum time to contact falls below it is an incident.
    pet_threshold: s, likewise for the post-encroachment time at a crossing.
    ttc_horizon: s, longer times to contact count as none.
    contact: shapes for TTC and collisions (vehicle rectangle as is, pedestrian disc 0.3 m).
    pair_range: m, pairs whose centres are farther apart are not evaluated (at 1.5 s TTC this
        allows closing speeds up to 30 m/s).
    collision_depth: m, a contact is a collision when the disc overlaps the rectangle by more.
    """

    ttc_threshold: float = 1.5
    pet_threshold: float = 1.0
    ttc_horizon: float = 10.0
    contact: ContactGeometry = ContactGeometry(vehicle_margin=0.0, pedestrian_radius=0.3)
    pair_range: float = 50.0
    collision_depth: float = 0.0

    def validate(self) -> None:
        """Raise HiyariError for impossible thresholds."""
        for name in ("ttc_threshold", "pet_threshold", "ttc_horizon", "pair_range"):
            if getattr(self, name) <= 0:
                raise HiyariError(f"incident config: {name} must be positive")
        if self.collision_depth < 0:
            raise HiyariError("incident config: collision_depth must be >= 0")


@dataclass
class Encounter:
    """One vehicle–pedestrian pair over the run. Times s, positions m, speeds m/s.

    ``time`` and the positions / speeds are those of the worst moment: the first contact if
    they collided, else the minimum TTC, else the PET event.
    """

    vehicle: str
    pedestrian: str
    first_seen: float
    time: float = math.nan
    min_ttc: float = math.inf
    min_sct: float = math.inf
    min_pet: float = math.inf
    collision: bool = False
    vehicle_x: float = math.nan
    vehicle_y: float = math.nan
    vehicle_speed: float = math.nan
    pedestrian_x: float = math.nan
    pedestrian_y: float = math.nan
    pedestrian_speed: float = math.nan
    pedestrian_lane: str = ""

    def is_incident(self, config: IncidentConfig) -> bool:
        """True when TTC or PET fell below their thresholds, or the pair collided."""
        return (
            self.collision
            or self.min_ttc < config.ttc_threshold
            or self.min_pet < config.pet_threshold
        )

    def _snapshot(self, state: WorldState, v: int, p: int) -> None:
        self.time = state.time
        self.vehicle_x, self.vehicle_y = (float(c) for c in state.xyz[v, :2])
        self.pedestrian_x, self.pedestrian_y = (float(c) for c in state.xyz[p, :2])
        self.vehicle_speed = float(state.speed[v])
        self.pedestrian_speed = float(state.speed[p])
        self.pedestrian_lane = str(state.lane[p])


def vehicle_pedestrian_pairs(state: WorldState, max_range: float) -> tuple[np.ndarray, np.ndarray]:
    """Row indices (vehicle rows, pedestrian rows) of every pair whose centres are within
    ``max_range`` m of each other."""
    veh = np.flatnonzero(state.is_vehicle)
    ped = np.flatnonzero(state.is_pedestrian)
    if len(veh) == 0 or len(ped) == 0:
        return np.zeros(0, int), np.zeros(0, int)
    d = state.xyz[veh, None, :2] - state.xyz[None, ped, :2]
    near = np.einsum("vpk,vpk->vp", d, d) <= max_range * max_range
    vi, pj = np.nonzero(near)
    return veh[vi], ped[pj]


def straight_line_metrics(
    state: WorldState,
    vi: np.ndarray,
    pj: np.ndarray,
    config: IncidentConfig = IncidentConfig(),
) -> tuple[np.ndarray, np.ndarray]:
    """Time to contact (s) at constant velocity, vehicles going straight along their heading,
    and whether each pair touches now (a collision), for pairs (``vi``, ``pj``).

    For vehicles whose route is known, hiyari.risk.sct.model.SCTModel.pair_metrics predicts
    them along their lane path instead (turning vehicles do not aim at the footway) and
    protects pedestrians on the junction's walking areas.
    """
    vel = state.velocity
    ttc = time_to_contact(
        state.xyz[vi, :2],
        state.heading[vi],
        vel[vi],
        state.length[vi],
        state.width[vi],
        state.xyz[pj, :2],
        vel[pj],
        config.contact,
        config.ttc_horizon,
    )
    gap = contact_gap(
        state.xyz[vi, :2],
        state.heading[vi],
        state.length[vi],
        state.width[vi],
        state.xyz[pj, :2],
        config.contact,
    )
    return ttc, gap < -config.collision_depth


class IncidentDetector:
    """Accumulates encounters step by step; each pair is one record however long it lasts."""

    def __init__(self, config: IncidentConfig = IncidentConfig()) -> None:
        config.validate()
        self.config = config
        self._enc: dict[tuple[str, str], Encounter] = {}

    def _get(self, vid: str, pid: str, time: float) -> Encounter:
        key = (vid, pid)
        e = self._enc.get(key)
        if e is None:
            e = self._enc[key] = Encounter(vid, pid, time)
        return e

    def update(
        self,
        state: WorldState,
        vi: np.ndarray,
        pj: np.ndarray,
        ttc: np.ndarray,
        touching: np.ndarray,
        sct: np.ndarray | None = None,
        pet_events: list[PetEvent] = (),
        sumo_collisions: list[tuple[str, str]] = (),
    ) -> None:
        """Add one step: pairs (vehicle rows ``vi``, pedestrian rows ``pj`` of ``state``) with
        their time to contact (s), whether they touch now, their SCT (s) if computed, this
        step's PET events and SUMO-reported collisions."""
        if len(vi):
            self._add_pairs(state, vi, pj, ttc, touching, sct)
        if pet_events:
            self._add_pet(state, pet_events)
        if sumo_collisions:
            self._add_collisions(state, sumo_collisions)

    def _add_pairs(
        self,
        state: WorldState,
        vi: np.ndarray,
        pj: np.ndarray,
        ttc: np.ndarray,
        touching: np.ndarray,
        sct: np.ndarray | None,
    ) -> None:
        if sct is None:
            sct = np.full(len(vi), np.inf)
        ids = state.ids
        t = state.time
        # a few pairs per step: plain floats, no array passes
        columns = (vi, pj, ttc, sct, touching)
        for v, p, ttc_k, sct_k, hit in zip(*(c.tolist() for c in columns), strict=True):
            if not (math.isfinite(ttc_k) or math.isfinite(sct_k) or hit):
                continue  # not near each other: no encounter
            e = self._get(ids[v], ids[p], t)
            if sct_k < e.min_sct:
                e.min_sct = sct_k
            if hit and not e.collision:
                e.collision = True
                e._snapshot(state, v, p)
            if ttc_k < e.min_ttc:
                e.min_ttc = ttc_k
                if not e.collision:
                    e._snapshot(state, v, p)

    def _add_pet(self, state: WorldState, pet_events: list[PetEvent]) -> None:
        row = {a: k for k, a in enumerate(state.ids.tolist())}
        for ev in pet_events:
            e = self._get(ev.vehicle, ev.pedestrian, ev.time)
            if ev.pet < e.min_pet:
                e.min_pet = ev.pet
                v, p = row.get(ev.vehicle), row.get(ev.pedestrian)
                if math.isnan(e.time) and v is not None and p is not None:
                    e._snapshot(state, v, p)

    def _add_collisions(self, state: WorldState, sumo_collisions: list[tuple[str, str]]) -> None:
        row = {a: k for k, a in enumerate(state.ids.tolist())}
        for a, b in sumo_collisions:
            ra, rb = row.get(a), row.get(b)
            if ra is None or rb is None or state.is_pedestrian[ra] == state.is_pedestrian[rb]:
                continue  # not a vehicle–pedestrian pair in this state
            v, p = (ra, rb) if state.is_pedestrian[rb] else (rb, ra)
            e = self._get(state.ids[v], state.ids[p], state.time)
            if not e.collision:
                e.collision = True
                e._snapshot(state, v, p)

    @property
    def encounters(self) -> list[Encounter]:
        """Every encounter so far, ordered by first sighting."""
        return sorted(self._enc.values(), key=lambda e: (e.first_seen, e.vehicle, e.pedestrian))

    def incidents(self) -> list[Encounter]:
        """The encounters that are incidents under this detector's thresholds."""
        return [e for e in self.encounters if e.is_incident(self.config)]


CSV_FIELDS = [f.name for f in fields(Encounter)]


def write_encounters_csv(
    path: str | Path, rows: list[Encounter], extra: dict[str, str] | None = None
) -> Path:
    """Write encounters as CSV (one row each; ``extra`` columns prepended with fixed values)."""
    extra = extra or {}
    with atomic_path(path) as tmp, tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=[*extra, *CSV_FIELDS])
        w.writeheader()
        for e in rows:
            w.writerow({**extra, **asdict(e)})
    return Path(path)
