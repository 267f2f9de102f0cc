"""Run a traffic-only simulation for a duration and summarise it (each contact with where it
happened and why, traffic.contact_context)."""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field

import numpy as np
from tqdm import tqdm

from hiyari.traffic.collision import Collision
from hiyari.traffic.contact_context import ContactContext, explain
from hiyari.traffic.simulation import SimConfig, Simulation


@dataclass
class TrafficSummary:
    """What a traffic run did. Times in seconds; counts are distinct actors."""

    sim_seconds: float
    wall_seconds: float
    steps: int
    vehicles_seen: int
    persons_seen: int
    max_vehicles: int
    max_persons: int
    collisions: list[Collision]
    times: np.ndarray = field(repr=False)  # (steps,) s
    vehicle_counts: np.ndarray = field(repr=False)  # (steps,) actors in the network
    person_counts: np.ndarray = field(repr=False)
    mean_vehicle_speed: np.ndarray = field(repr=False)  # (steps,) m/s, nan when empty
    #: (a, b) -> the context of the pair's first contact
    contexts: dict[tuple[str, str], ContactContext] = field(default_factory=dict)

    @property
    def steps_per_second(self) -> float:
        return self.steps / max(self.wall_seconds, 1e-9)

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall-clock second."""
        return self.sim_seconds / max(self.wall_seconds, 1e-9)

    def as_dict(self) -> dict:
        """JSON-ready summary (collisions listed once per pair, first contact)."""
        first: dict[tuple[str, str], Collision] = {}
        for c in self.collisions:
            first.setdefault((c.a, c.b), c)
        return {
            "sim_seconds": self.sim_seconds,
            "wall_seconds": round(self.wall_seconds, 3),
            "steps": self.steps,
            "steps_per_second": round(self.steps_per_second, 1),
            "realtime_factor": round(self.realtime_factor, 1),
            "vehicles_seen": self.vehicles_seen,
            "persons_seen": self.persons_seen,
            "max_vehicles": self.max_vehicles,
            "max_persons": self.max_persons,
            "collision_pairs": [
                {
                    "time": c.time,
                    "a": c.a,
                    "b": c.b,
                    "kind": c.kind,
                    "depth_m": round(c.depth, 3),
                    "reported_by_sumo": c.reported_by_sumo,
                    **(asdict(self.contexts[key]) if key in self.contexts else {}),
                }
                for key, c in first.items()
            ],
        }


def run_traffic(config: SimConfig, duration: float, progress: bool = True) -> TrafficSummary:
    """Run ``config`` for ``duration`` simulated seconds with a progress bar."""
    from hiyari.errors import HiyariError

    if duration <= 0:
        raise HiyariError(f"duration must be positive, got {duration} s")
    vehicles: set[str] = set()
    persons: set[str] = set()
    times, nveh, nper, vmean = [], [], [], []
    collisions: list[Collision] = []
    contexts: dict[tuple[str, str], ContactContext] = {}
    with Simulation(config) as sim:
        end = sim.time + duration
        n_steps = int(round(duration / config.step_length))
        t0 = time.perf_counter()
        with tqdm(total=n_steps, unit="step", disable=not progress, desc="sim") as bar:
            for state in sim.run(until=end):
                ped = state.is_pedestrian
                vehicles.update(state.ids[~ped].tolist())
                persons.update(state.ids[ped].tolist())
                times.append(state.time)
                nveh.append(int((~ped).sum()))
                nper.append(int(ped.sum()))
                vmean.append(float(state.speed[~ped].mean()) if (~ped).any() else np.nan)
                collisions.extend(sim.collisions)
                for c in sim.collisions:
                    if (c.a, c.b) not in contexts:
                        contexts[(c.a, c.b)] = explain(c, state)
                bar.update(1)
                if len(times) % 50 == 0:
                    bar.set_postfix(veh=nveh[-1], ped=nper[-1], coll=len(collisions))
        wall = time.perf_counter() - t0
    return TrafficSummary(
        sim_seconds=float(len(times) * config.step_length),
        wall_seconds=wall,
        steps=len(times),
        vehicles_seen=len(vehicles),
        persons_seen=len(persons),
        max_vehicles=max(nveh, default=0),
        max_persons=max(nper, default=0),
        collisions=collisions,
        times=np.array(times),
        vehicle_counts=np.array(nveh),
        person_counts=np.array(nper),
        mean_vehicle_speed=np.array(vmean),
        contexts=contexts,
    )
