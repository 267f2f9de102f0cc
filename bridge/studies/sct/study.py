"""The pedestrian incident study (DIVP C2): SUMO's drivers against SCT drivers, same demand.

Study design (docs/models.md §2; choices where the seed is silent are documented in StudyConfig):
a four-leg intersection with sidewalks and a crossing on every leg, signalised and
unsignalised variants, 200 passenger cars per hour and a pedestrian demand between the
fringes, simulated for 2 days at 0.1 s. The simulated time is split into independent runs
(one seed each, the same seeds in both arms). The baseline arm keeps SUMO's driver model; the
SCT arm hands every vehicle in scope (the penetration rate) to the SCT controller.

Speed: pedestrians meet vehicles only at the junction (SUMO's pedestrians enter the
carriageway nowhere else), so the metrics, the incident detector and the controller run only
on steps where a vehicle is within ``vehicle_zone`` of a junction with crossings and a
pedestrian within ``pedestrian_zone``. Between such steps SUMO is advanced in one call up to
the earliest time both could be there again (bounded by actors' distances, the departure
schedule and speed bounds), without reading any state.
"""

from __future__ import annotations

import math
import os
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import sumolib
from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.bridge.loop.drivers.sct_controller import SCTController, SCTControllerConfig
from hiyari.bridge.studies.pool import Crashed, PoolOptions, report_progress, run_all
from hiyari.bridge.studies.sct.scan import zone_scan
from hiyari.errors import HiyariError, about
from hiyari.net.sumo.build import IntersectionParams, build_intersection
from hiyari.net.sumo.files import check_net
from hiyari.risk.metrics.contact import PostEncroachmentTracker, SCTConfig
from hiyari.risk.metrics.incidents import (
    Encounter,
    IncidentConfig,
    IncidentDetector,
)
from hiyari.risk.metrics.pedestrian_geometry import NetGeometry
from hiyari.risk.sct.model import SCTModel
from hiyari.sumo_tools import run_sumo_tool
from hiyari.traffic.actor_class import ActorClass
from hiyari.traffic.demand import DemandConfig, check_crossings, crossing_ids, write_demand
from hiyari.traffic.simulation import SimConfig, Simulation
from hiyari.traffic.sumocfg import SumoScenario, read_sumocfg
from hiyari.traffic.world_state import WorldState

VARIANTS = {"unsignalised": False, "signalised": True}
#: The variant of a study on the user's map or SUMO scenario (its junctions as they are).
WORLD_VARIANT = "map"
_PEDESTRIAN = np.int8(ActorClass.PEDESTRIAN)  # compared as a numpy scalar: no enum lookup
ARMS = ("baseline", "sct")


@dataclass(frozen=True)
class StudyConfig:
    """The study's parameters. Rates per hour, times in seconds, distances in metres.

    days: simulated days per arm and variant (the seed's study: 2).
    vehicles_per_hour / persons_per_hour: Poisson demand between the fringes (seed: 200 veh/h;
        the pedestrian volume is the toolkit's default, docs/models.md §2).
    variants: intersection variants to run ("unsignalised", "signalised"); by default the
        unsignalised one.
    crossing_priority: True (default): the unsignalised junction's crossings are zebra
        crossings, where drivers must yield to pedestrians on them or stepping onto them
        (Vienna Convention art. 21, Japan's Road Traffic Act art. 38); SUMO's drivers then
        yield as those rules require. False: netconvert's default for guessed crossings at
        unsignalised junctions, where pedestrians must wait for a gap and SUMO's turning
        drivers, holding the right of way, drive through pedestrians who misjudged one
        (308 contacts in 2 days at 200 veh/h). Signalised crossings follow the lights either way.
    runs: the simulated time is split into this many independent runs, run k with seed
        ``seed + k`` (demand and SUMO), identical in both arms; runs go in parallel.
    penetration: share of vehicles driven by the SCT model in the SCT arm.
    arm_length: length of each intersection leg.
    vehicle_zone / pedestrian_zone: radii around the junction within which vehicles and
        pedestrians are evaluated (outside them SUMO's pedestrians never meet the carriageway,
        and a vehicle at vehicle_zone needs > sct_safe to reach the crossings).
    max_vehicle_speed / max_pedestrian_speed: bounds used to skip steps safely.
    metric_horizon: s, a pair is evaluated on a step only if it could touch within this time
        (or within sct_safe, for the controller); longer TTC / SCT / PET are logged as none,
        and the steps where no pair is that close are skipped.
    sct_log_period: s, the SCT written to the encounter log is sampled this often (TTC, PET,
        contacts and the controller's own SCT every step); it is for the histograms only.
    map_net / sumocfg: study on the user's SUMO net (generated vehicle demand) or inside the
        user's SUMO scenario (its own vehicles and persons, over its time window from its
        begin) instead of the generated intersection; the one variant is then WORLD_VARIANT
        and the junctions keep the right of way the net gives them ("": not used).
    crossings: on a map or scenario, the pedestrian crossings (SUMO crossing edge ids) the
        study's pedestrians walk across, persons_per_hour of them in all; the junctions of
        these crossings are studied (empty: every crossing with a sidewalk at both ends).
    """

    days: float = 2.0
    vehicles_per_hour: float = 200.0
    persons_per_hour: float = 300.0
    variants: tuple[str, ...] = ("unsignalised",)
    crossing_priority: bool = True
    runs: int = 2
    seed: int = 1
    step_length: float = 0.1
    penetration: float = 1.0
    arm_length: float = 150.0
    vehicle_zone: float = 80.0
    pedestrian_zone: float = 20.0
    max_vehicle_speed: float = 25.0
    max_pedestrian_speed: float = 2.5
    metric_horizon: float = 3.0
    sct_log_period: float = 0.5
    map_net: str = ""
    sumocfg: str = ""
    crossings: tuple[str, ...] = ()
    sct: SCTConfig = field(default_factory=SCTConfig)
    controller: SCTControllerConfig = field(default_factory=SCTControllerConfig)
    incidents: IncidentConfig = field(default_factory=IncidentConfig)

    @property
    def run_seconds(self) -> float:
        """Simulated seconds of each run."""
        return self.days * 86400.0 / self.runs

    def validate(self) -> None:
        """Raise HiyariError for impossible parameters."""
        if self.days <= 0 or self.runs < 1:
            raise HiyariError("study: days must be > 0 and runs >= 1")
        if self.vehicles_per_hour <= 0 or self.persons_per_hour < 0:
            raise HiyariError("study: vehicles per hour must be > 0, persons per hour >= 0")
        if self.map_net and self.sumocfg:
            raise HiyariError("study: a map or a SUMO scenario, not both")
        if self.map_net or self.sumocfg:
            if self.variants != (WORLD_VARIANT,):
                raise HiyariError(f"study: on a map the one variant is {WORLD_VARIANT!r}")
        else:
            unknown = [v for v in self.variants if v not in VARIANTS]
            if unknown or not self.variants:
                known = ", ".join(VARIANTS)
                raise HiyariError(f"study: unknown variant(s) {unknown} (known: {known})")
            if self.crossings:
                raise HiyariError("study: crossings are chosen on a map or a SUMO scenario")
        if not 0.0 <= self.penetration <= 1.0:
            raise HiyariError(f"study: penetration must be in 0..1, got {self.penetration}")
        if self.run_seconds < 60:
            raise HiyariError("study: each run must cover at least 60 simulated seconds")
        self.incidents.validate()
        replace(self.controller, penetration=self.penetration).validate()


@dataclass(frozen=True)
class StudyWorld:
    """A study on the user's map: its ``net``, the user's SUMO scenario ``sumo`` (None: a
    map with generated demand) and the ``crossings`` the study's pedestrians walk across."""

    net: Path
    sumo: SumoScenario | None
    crossings: tuple[str, ...]

    @property
    def junctions(self) -> tuple[str, ...]:
        """The junctions of the crossings (SUMO names a crossing ':<junction>_c<k>')."""
        return tuple(sorted({c[1:].rsplit("_c", 1)[0] for c in self.crossings}))

    @property
    def begin(self) -> float:
        """Simulation time (s) the runs start at: the scenario's begin, else 0."""
        return self.sumo.begin if self.sumo is not None else 0.0


def study_world(config: StudyConfig) -> StudyWorld | None:
    """The map or SUMO scenario of ``config``, checked (None: the generated intersection):
    HiyariError in one line naming the file for a broken net or scenario, an unknown crossing
    id or one without a sidewalk at both ends, a net without such crossings, and runs that
    do not fit into the scenario's time window."""
    if not (config.map_net or config.sumocfg):
        return None
    sumo = read_sumocfg(config.sumocfg) if config.sumocfg else None
    net = sumo.net if sumo is not None else Path(config.map_net)
    with about(config.sumocfg or net):  # a scenario's net is named with the scenario
        check_net(net)
    if sumo is not None:
        if sumo.end is None:
            raise HiyariError(f"{sumo.config}: the study runs in the scenario's time window, "
                              "which has no end")  # fmt: skip
        if sumo.begin + config.run_seconds > sumo.end + 1e-6:
            raise HiyariError(
                f"{sumo.config}: a run of {config.run_seconds:g} s from begin {sumo.begin:g} s "
                f"ends after the scenario's end {sumo.end:g} s"
            )
    if config.crossings:
        check_crossings(net, config.crossings)
        crossings = config.crossings
    else:
        crossings = tuple(crossing_ids(net, walkable=True))
        if not crossings:
            raise HiyariError(f"{net}: no pedestrian crossing with a sidewalk at both ends")
    return StudyWorld(net, sumo, crossings)


@dataclass(frozen=True)
class ArmTask:
    """One run: a variant, an arm, a seed, its input files; on a map, its ``world``."""

    variant: str
    arm: str
    run: int
    seed: int
    net: Path
    routes: Path
    study: StudyConfig
    world: StudyWorld | None = None

    def sim_config(self, extra_args: tuple[str, ...] = ()) -> SimConfig:
        """What SUMO runs: the net with the run's demand, or the user's scenario with the
        study's pedestrians added to its own route files; ``study.run_seconds`` from the
        scenario's begin (0 on other nets)."""
        cfg = self.study
        sumo = self.world.sumo if self.world is not None else None
        if sumo is None:
            return SimConfig(
                net=self.net, routes=[self.routes], step_length=cfg.step_length, seed=self.seed,
                end_time=cfg.run_seconds, extra_args=extra_args,
            )  # fmt: skip
        # SUMO's -r replaces the configuration's route files: they are named again
        return SimConfig(
            config=sumo.config, routes=[*sumo.routes, self.routes], step_length=cfg.step_length,
            seed=self.seed, begin=sumo.begin, end_time=sumo.begin + cfg.run_seconds,
            extra_args=extra_args, generated=[self.routes],
        )  # fmt: skip


@dataclass
class ArmResult:
    """What one run produced. Times in seconds."""

    variant: str
    arm: str
    run: int
    seed: int
    sim_seconds: float
    wall_seconds: float
    steps: int
    evaluated_steps: int
    encounters: list[Encounter]
    incident_flags: np.ndarray  # (E,) bool, per encounter
    travel_time: np.ndarray  # (vehicles,) s, depart to arrival
    time_loss: np.ndarray  # (vehicles,) s, SUMO's timeLoss (delay against free flow)
    person_time_loss: np.ndarray  # (persons,) s
    interventions: int = 0
    cpu_seconds: float = 0.0  # this process's CPU time over the same span as wall_seconds
    crashed: str = ""  # why the run's worker process died ("": it did not); nothing else set

    @classmethod
    def lost(cls, task: ArmTask, crash: Crashed) -> ArmResult:
        """The result of a run whose worker process died: no time simulated, nothing seen."""
        empty = np.zeros(0)
        return cls(task.variant, task.arm, task.run, task.seed, 0.0, 0.0, 0, 0, [],
                   np.zeros(0, bool), empty, empty, empty, crashed=str(crash))  # fmt: skip

    @property
    def incidents(self) -> list[Encounter]:
        return [e for e, f in zip(self.encounters, self.incident_flags, strict=True) if f]


# ---------------------------------------------------------------------------- inputs
def build_inputs(config: StudyConfig, folder: Path) -> list[ArmTask]:
    """Build the nets and demand files under ``folder`` and list every run of the study."""
    config.validate()
    world = study_world(config)
    folder.mkdir(parents=True, exist_ok=True)
    if world is not None:
        return _world_inputs(config, world, folder)
    tasks = []
    for variant in config.variants:
        net = build_intersection(
            folder / f"{variant}.net.xml",
            IntersectionParams(
                arm_length=config.arm_length, traffic_light=VARIANTS[variant], crossings=True
            ),
        )
        if config.crossing_priority and not VARIANTS[variant]:
            give_crossings_priority(net)
        for k in range(config.runs):
            seed = config.seed + k
            demand = DemandConfig(
                vehicles_per_hour=config.vehicles_per_hour,
                persons_per_hour=config.persons_per_hour,
                begin=0.0,
                end=config.run_seconds,
                seed=seed,
                vehicle_mix={"car": 1.0},
            )
            routes = write_demand(net, folder / f"{variant}_run{k}.rou.xml", demand)
            tasks += [ArmTask(variant, arm, k, seed, net, routes, config) for arm in ARMS]
    return tasks


def _world_inputs(config: StudyConfig, world: StudyWorld, folder: Path) -> list[ArmTask]:
    """The runs on a map: per run, the study's demand on the user's net (never modified)
    written under ``folder``: vehicles between the fringes (none in a SUMO scenario, whose own
    vehicles are the study's) and pedestrians across the chosen crossings."""
    tasks = []
    for k in range(config.runs):
        seed = config.seed + k
        demand = DemandConfig(
            vehicles_per_hour=0.0 if world.sumo is not None else config.vehicles_per_hour,
            persons_per_hour=config.persons_per_hour,
            begin=world.begin,
            end=world.begin + config.run_seconds,
            seed=seed,
            vehicle_mix={"car": 1.0},
            crossings=world.crossings,
        )
        routes = write_demand(world.net, folder / f"{WORLD_VARIANT}_run{k}.rou.xml", demand)
        tasks += [
            ArmTask(WORLD_VARIANT, arm, k, seed, world.net, routes, config, world) for arm in ARMS
        ]
    return tasks


def give_crossings_priority(net: Path) -> Path:
    """Rewrite ``net`` in place so that every pedestrian crossing has priority over vehicles
    (zebra crossings); netconvert re-computes the junctions' right of way."""
    root = etree.parse(str(net)).getroot()
    crossings = etree.Element("connections")
    for edge in root.iter("edge"):
        if edge.get("function") != "crossing":
            continue
        node = edge.get("id")[1:].rsplit("_c", 1)[0]
        lane = edge.find("lane")
        etree.SubElement(
            crossings,
            "crossing",
            node=node,
            edges=edge.get("crossingEdges"),
            priority="true",
            width=lane.get("width"),
        )
    if len(crossings) == 0:
        return net
    with tempfile.TemporaryDirectory(prefix="hiyari-crossings-") as tmp:
        con = Path(tmp) / "crossings.con.xml"
        etree.ElementTree(crossings).write(str(con))
        with atomic_path(net) as out:
            run_sumo_tool(
                "netconvert",
                ["-s", str(net), "-x", str(con), "-o", str(out)],
                f"{net}: crossing priorities",
            )
    return net


@dataclass(frozen=True)
class _Schedule:
    """Earliest times (s) at which not-yet-departed actors could reach their zone."""

    depart: np.ndarray  # (n,) sorted
    earliest_suffix: np.ndarray  # (n,) min over k >= i of depart + travel to the zone
    lead: float  # s, the shortest travel from any departure point to the zone
    #: departures not known ahead (a SUMO scenario's own demand): an actor may come any time
    anytime: bool = False

    def next_entry(self, now: float) -> float:
        if self.anytime:
            return now
        i = int(np.searchsorted(self.depart, now, side="right"))
        return float(self.earliest_suffix[i]) if i < len(self.depart) else math.inf


def _schedules(task: ArmTask, geometry: NetGeometry, net: Any) -> tuple[_Schedule, _Schedule]:
    cfg = task.study
    if task.world is not None and task.world.sumo is not None:
        # the scenario's route files are SUMO's to read (flows, routes by id, stops ...)
        anytime = _Schedule(np.zeros(0), np.zeros(0), 0.0, anytime=True)
        return anytime, anytime
    root = etree.parse(str(task.routes)).getroot()

    def start_distance(edge_id: str, pos: str | None) -> float:
        """From the departure point (the edge's start, or ``pos`` m along its first lane)
        to the nearest studied junction, m."""
        edge = net.getEdge(edge_id)
        x, y = edge.getShape()[0][:2]
        if pos is not None:  # lane lengths are along the shape, scaled where a junction cut it
            lane = edge.getLanes()[0]
            shape = lane.getShape()
            scale = sumolib.geomhelper.polyLength(shape) / max(lane.getLength(), 1e-9)
            x, y = sumolib.geomhelper.positionAtShapeOffset(shape, float(pos) * scale)[:2]
        return float(np.min(np.linalg.norm(geometry.junction_xy - (x, y), axis=1)))

    def schedule(
        items: list[tuple[float, str, str | None]], zone: float, speed: float
    ) -> _Schedule:
        if not items:
            return _Schedule(np.zeros(0), np.zeros(0), math.inf)
        dep = np.array([t for t, _, _ in items])
        lead = np.array([max(start_distance(e, p) - zone, 0.0) / speed for _, e, p in items])
        order = np.argsort(dep, kind="stable")
        dep, lead = dep[order], lead[order]
        suffix = np.minimum.accumulate((dep + lead)[::-1])[::-1]
        return _Schedule(dep, suffix, float(lead.min()))

    trips = [(float(t.get("depart")), t.get("from"), None) for t in root.iter("trip")]
    # circulating vehicles (demand on nets without fringes) depart on their route's first edge
    trips += [
        (float(v.get("depart")), v.find("route").get("edges").split()[0], None)
        for v in root.iter("vehicle")
    ]
    persons = [
        (float(p.get("depart")), p.find("walk").get("from"), p.get("departPos"))
        for p in root.iter("person")
        if p.find("walk") is not None
    ]
    return (
        schedule(trips, cfg.vehicle_zone, cfg.max_vehicle_speed),
        schedule(persons, cfg.pedestrian_zone, cfg.max_pedestrian_speed),
    )


def _crossing_links(sim: Simulation, geometry: NetGeometry) -> list[tuple[str, list[int]]]:
    """Per crossing: the traffic light and link indices that control it (empty: none)."""
    out: list[tuple[str, list[int]]] = [("", []) for _ in geometry.crossing_ids]
    lane_to_k = {f"{c}_0": k for k, c in enumerate(geometry.crossing_ids)}
    for link in sim.signal_links():
        k = lane_to_k.get(link.to_lane, lane_to_k.get(link.from_lane))
        if k is not None:
            out[k] = (link.tls, [*out[k][1], link.index])
    return out


def _open_crossings(sim: Simulation, links: list[tuple[str, list[int]]]) -> np.ndarray | None:
    if not any(idx for _, idx in links):
        return None
    states = sim.signal_states(sorted({tls for tls, idx in links if idx}))
    return np.array([not idx or any(states[t][i] in "Gg" for i in idx) for t, idx in links])


# ---------------------------------------------------------------------------- one run
def run_arm(task: ArmTask, progress: Callable[[float], None] | None = None) -> ArmResult:
    """Run one arm of one variant for ``study.run_seconds`` and return its encounters and
    trip statistics. ``progress`` receives simulated seconds as they pass."""
    cfg = task.study
    geometry = NetGeometry.from_net(task.net, task.world.junctions if task.world else None)
    if len(geometry.junction_xy) == 0:
        raise HiyariError(f"{task.net}: the network has no crossings to study")
    model = SCTModel(geometry, cfg.sct)
    detector = IncidentDetector(cfg.incidents)
    pet = PostEncroachmentTracker(cfg.metric_horizon)
    controller = None
    if task.arm == "sct":
        ctrl_cfg = replace(cfg.controller, penetration=cfg.penetration)
        controller = SCTController(model, ctrl_cfg, seed=task.seed)
    veh_sched, ped_sched = _schedules(task, geometry, geometry._net)
    centres = geometry.junction_xy
    rv2, rp2 = cfg.vehicle_zone**2, cfg.pedestrian_zone**2
    sct_every = max(1, int(round(cfg.sct_log_period / cfg.step_length)))
    horizon = (
        cfg.metric_horizon
        if task.arm == "baseline"
        else max(cfg.metric_horizon, cfg.controller.sct_safe)
    )
    begin = task.world.begin if task.world is not None else 0.0
    dt, end = cfg.step_length, begin + cfg.run_seconds
    eps = 1e-6
    evaluated = 0
    reported = begin
    with tempfile.TemporaryDirectory(prefix="hiyari-study-") as tmp:
        trip_file = Path(tmp) / "tripinfo.xml"
        sim_cfg = task.sim_config(("--tripinfo-output", str(trip_file)))
        t0, c0 = time.perf_counter(), time.process_time()
        with Simulation(sim_cfg, detect_collisions=False) as sim:
            links = _crossing_links(sim, geometry)
            while sim.time < end - eps:
                st = sim.step()
                now = st.time
                if progress is not None and now - reported >= 600.0:
                    progress(now - reported)
                    reported = now
                is_ped = st.cls == _PEDESTRIAN
                d2, vin, pin, vi, pj, reachable, tau_acc = zone_scan(
                    st.xyz[:, :2],
                    is_ped,
                    centres,
                    rv2,
                    rp2,
                    st.length,
                    st.width,
                    cfg.sct.vehicle_margin,
                    cfg.sct.pedestrian_radius,
                    st.speed,
                    cfg.max_pedestrian_speed,
                    cfg.controller.max_accel,
                    cfg.metric_horizon,
                    cfg.controller.sct_safe,
                )
                t_pairs = math.inf
                if len(vin) and len(pin):
                    plan = controller is not None and bool(reachable or controller.controlled)
                    if len(vi) or plan:
                        evaluated += 1
                        _evaluate(
                            sim,
                            st,
                            vin,
                            pin,
                            vi,
                            pj,
                            model,
                            detector,
                            pet,
                            controller if plan else None,
                            links,
                            geometry.walkingarea_lanes,
                            int(round(now / dt)) % sct_every == 0,
                        )
                        continue
                    t_pairs = tau_acc - horizon
                # nobody to evaluate: skip to when a vehicle and a pedestrian could be close
                if controller is not None and controller.controlled:
                    controller.release_all(sim, set(st.ids[~is_ped].tolist()))
                pet.reset()
                d = np.sqrt(d2)
                pending = sim.pending_vehicles() > 0
                t_v = _time_to_zone(
                    d[~is_ped & (d2 > rv2)],
                    cfg.vehicle_zone,
                    cfg.max_vehicle_speed,
                    veh_sched,
                    now,
                    pending,
                )
                t_p = _time_to_zone(
                    d[is_ped & (d2 > rp2)],
                    cfg.pedestrian_zone,
                    cfg.max_pedestrian_speed,
                    ped_sched,
                    now,
                    False,
                )
                if len(vin) and len(pin):
                    wake = min(t_pairs, t_v, t_p)
                else:  # a pair needs an actor of the missing kind in its zone first
                    wake = max(0.0 if len(vin) else t_v, 0.0 if len(pin) else t_p)
                skip = int(min(wake, end - now) / dt + eps) - 1
                if skip >= 1:
                    sim.skip_ahead(round(now + skip * dt, 6))
                    model.forget_absent(set(sim.vehicle_ids()))
            if progress is not None:  # the last seconds, as they end (not after the trips)
                progress(end - reported)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        trips = _read_tripinfo(trip_file)
    encounters = detector.encounters
    return ArmResult(
        variant=task.variant,
        arm=task.arm,
        run=task.run,
        seed=task.seed,
        sim_seconds=cfg.run_seconds,
        wall_seconds=wall,
        steps=int(round(end / dt)),
        evaluated_steps=evaluated,
        encounters=encounters,
        incident_flags=np.array([e.is_incident(cfg.incidents) for e in encounters], bool),
        travel_time=trips[0],
        time_loss=trips[1],
        person_time_loss=trips[2],
        interventions=controller.interventions if controller is not None else 0,
        cpu_seconds=cpu,
    )


def _time_to_zone(
    dist: np.ndarray, zone: float, speed: float, sched: _Schedule, now: float, pending: bool
) -> float:
    """Earliest time (s from now) any actor of one kind could be within ``zone`` m."""
    t = float(((dist - zone) / speed).min()) if len(dist) else math.inf
    t = min(t, sched.next_entry(now) - now)
    if pending:  # insertion-delayed actors depart as soon as there is room
        t = min(t, sched.lead)
    return max(t, 0.0)


def _evaluate(
    sim: Simulation,
    st: WorldState,
    vin: np.ndarray,
    pin: np.ndarray,
    vi: np.ndarray,
    pj: np.ndarray,
    model: SCTModel,
    detector: IncidentDetector,
    pet: PostEncroachmentTracker,
    controller: SCTController | None,
    links: list[tuple[str, list[int]]],
    walkingareas: set[str] | frozenset[str],
    log_sct: bool,
) -> None:
    """Metrics, incidents and (SCT arm) control on one step: vehicle rows ``vin`` and
    pedestrian rows ``pin`` of ``st`` in scope, pairs (``vi``, ``pj``) near enough to log;
    SCT is logged only when ``log_sct``. Every pass reads those rows of ``st`` itself (no
    state cut down to them)."""
    ids = st.ids
    for vid in ids[vin].tolist():
        if not model.has_route(vid):
            model.set_route(vid, sim.route_of(vid))
    view = model.prepare(
        st, _open_crossings(sim, links), log_sct or controller is not None, (vin, pin)
    )
    icfg = detector.config
    ttc, sct, gap = model.pair_metrics(view, vi, pj, icfg.contact, log_sct)
    ttc[ttc > icfg.ttc_horizon] = np.inf
    has, v_in, p_in = model.crossing_occupancy(view, vi, pj, icfg.contact.pedestrian_radius)
    zone = np.flatnonzero(has)
    keys = [(ids[vi[k]], ids[pj[k]]) for k in zone.tolist()]
    events = pet.update(st.time, keys, v_in[zone], p_in[zone])
    # SUMO's own contact reports between actors in scope, except its corner walking-area
    # overlaps (geometry)
    collisions = sim.sumo_contacts()
    if collisions:
        scope = np.concatenate([vin, pin])
        lane = dict(zip(ids[scope].tolist(), st.lane[scope].tolist(), strict=True))
        outside = {None, *walkingareas}  # not in scope, or on a walking area
        collisions = [
            (collider, victim)
            for collider, victim in collisions
            if lane.get(victim) not in outside and lane.get(collider) not in outside
        ]
    detector.update(st, vi, pj, ttc, gap < -icfg.collision_depth, sct, events, collisions)
    if controller is not None:
        # vehicles still in the simulation, for hand-backs (only controlled ones are handed back)
        present = set(ids[st.cls != _PEDESTRIAN].tolist()) if controller.controlled else set()
        controller.step(sim, view, present)


def _read_tripinfo(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vehicle durations, vehicle time losses, person walking time losses), s.

    Streamed, each trip dropped once read: a 48-hour run's file (about 9 MB) parsed as one
    tree took some 75 MB that the process kept after the tree was freed (the soak's jump at
    its last sample, docs/performance.md)."""
    if not path.is_file():
        return np.zeros(0), np.zeros(0), np.zeros(0)
    dur, loss, ploss = [], [], []
    for _, el in etree.iterparse(str(path), tag=("tripinfo", "personinfo")):
        if el.tag == "tripinfo":
            dur.append(float(el.get("duration")))
            loss.append(float(el.get("timeLoss")))
        else:
            ploss.append(sum(float(w.get("timeLoss", 0)) for w in el.iter("walk")))
        el.clear()
        while el.getprevious() is not None:  # the trips read before this one
            del el.getparent()[0]
    return np.array(dur), np.array(loss), np.array(ploss)


# ---------------------------------------------------------------------------- the study
def _run_reporting(task: ArmTask) -> ArmResult:
    return run_arm(task, report_progress)


def run_tasks(
    tasks: list[ArmTask],
    jobs: int | None = None,
    on_progress: Callable[[float], None] | None = None,
    in_process: bool = False,
) -> list[ArmResult]:
    """Run every task, ``jobs`` worker processes in parallel (default: one per CPU); results
    in task order. ``on_progress`` receives simulated seconds done, summed over runs. A run
    whose worker dies gives :meth:`ArmResult.lost` (its ``crashed`` says why).
    ``in_process``: one run after the other in this process (a crash ends them all)."""
    # the SCT arms take longest: start them first so the pool ends evenly
    order = sorted(range(len(tasks)), key=lambda k: tasks[k].arm != "sct")
    pool = PoolOptions(workers=jobs or os.cpu_count() or 1, in_process=in_process)
    results: list[ArmResult | None] = [None] * len(tasks)
    for i, result in run_all(_run_reporting, [tasks[k] for k in order], pool, on_progress):
        task = tasks[order[i]]
        results[order[i]] = ArmResult.lost(task, result) if isinstance(result, Crashed) else result
    return results


def run_study(
    config: StudyConfig,
    folder: str | Path,
    jobs: int | None = None,
    progress: bool = True,
    in_process: bool = False,
) -> tuple[list[ArmResult], float]:
    """Build the inputs under ``folder``/inputs and run every arm, variant and run in
    parallel processes (``in_process``: here, one after the other); returns the results and
    the wall time (s)."""
    from tqdm import tqdm

    tasks = build_inputs(config, Path(folder) / "inputs")
    total = config.days * 86400.0 * len(config.variants) * len(ARMS)
    t0 = time.perf_counter()
    with tqdm(total=round(total), unit="sim s", disable=not progress, desc="study") as bar:
        results = run_tasks(tasks, jobs, lambda s: bar.update(round(s)), in_process)
    return results, time.perf_counter() - t0


def run_bare(task: ArmTask, read_state: bool = False) -> tuple[float, float]:
    """Wall and CPU time (s) of the same SUMO run as ``task`` with no metrics and no
    controller: libsumo stepping only, or (``read_state``) stepping with a WorldState read
    per step."""
    sim_cfg = task.sim_config()
    end = sim_cfg.end_time
    with Simulation(sim_cfg, detect_collisions=False) as sim:
        t0, c0 = time.perf_counter(), time.process_time()
        if read_state:
            while sim.time < end - 1e-6:
                sim.step()
        else:
            sim.run_bare(end)
        return time.perf_counter() - t0, time.process_time() - c0
