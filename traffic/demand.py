"""Seeded demand: vehicles and persons per hour between the fringe edges of a network."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import sumolib
from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.traffic.actor_class import ActorClass


@dataclass(frozen=True)
class VehicleType:
    """A SUMO vType: vehicle class and size in metres, speeds in m/s, accelerations in m/s^2."""

    vclass: str
    length: float
    width: float
    height: float
    max_speed: float
    accel: float = 2.6
    decel: float = 4.5
    gui_shape: str = "passenger"


#: The built-in types demand can mix; keys are what ``DemandConfig.vehicle_mix`` accepts.
#: Sizes are the class defaults (hiyari.traffic.actor_class.CLASS_SIZE).
VEHICLE_TYPES: dict[str, VehicleType] = {
    "car": VehicleType("passenger", *ActorClass.CAR.size.as_tuple(), 50.0),
    "truck": VehicleType("truck", *ActorClass.TRUCK.size.as_tuple(), 36.0, 1.3, 4.0, "truck"),
    "bus": VehicleType("bus", *ActorClass.BUS.size.as_tuple(), 30.0, 1.2, 4.0, "bus"),
    "motorcycle": VehicleType(
        "motorcycle", *ActorClass.MOTORCYCLE.size.as_tuple(), 50.0, 4.0, 7.0, "motorcycle"
    ),
    "bicycle": VehicleType(
        "bicycle", *ActorClass.BICYCLE.size.as_tuple(), 6.0, 1.2, 3.0, "bicycle"
    ),
}
PEDESTRIAN_TYPE = VehicleType(
    "pedestrian", *ActorClass.PEDESTRIAN.size.as_tuple(), 1.5, 1.5, 2.0, "pedestrian"
)


@dataclass(frozen=True)
class DemandConfig:
    """Poisson arrivals between fringe edges. Rates per hour, times in seconds."""

    vehicles_per_hour: float = 600.0
    persons_per_hour: float = 300.0
    begin: float = 0.0
    end: float = 3600.0
    seed: int = 1
    vehicle_mix: dict[str, float] = field(default_factory=lambda: {"car": 1.0})

    def validate(self) -> None:
        """Raise HiyariError for impossible rates, times or unknown vehicle types."""
        if self.vehicles_per_hour < 0 or self.persons_per_hour < 0:
            raise HiyariError("demand rates must be >= 0 per hour")
        if self.end <= self.begin:
            raise HiyariError(f"demand end {self.end} s must be after begin {self.begin} s")
        for name, share in self.vehicle_mix.items():
            if name not in VEHICLE_TYPES:
                known = ", ".join(VEHICLE_TYPES)
                raise HiyariError(f"unknown vehicle type {name!r} in the mix (known: {known})")
            if share < 0:
                raise HiyariError(f"vehicle mix share for {name!r} must be >= 0")
        if self.vehicles_per_hour > 0 and sum(self.vehicle_mix.values()) <= 0:
            raise HiyariError("vehicle mix shares sum to zero")


def _arrivals(rng: np.random.Generator, rate_per_hour: float, begin: float, end: float):
    if rate_per_hour <= 0:
        return np.zeros(0)
    mean_gap = 3600.0 / rate_per_hour
    n_max = int((end - begin) / mean_gap * 2 + 20)
    t = begin + np.cumsum(rng.exponential(mean_gap, n_max))
    while t[-1] < end:  # rare: extend the draw
        t = np.concatenate([t, t[-1] + np.cumsum(rng.exponential(mean_gap, n_max))])
    return np.round(t[t < end], 1)


def _od_pairs(net: sumolib.net.Net, vclass: str, directed: bool) -> list[tuple[str, str]]:
    """Fringe-to-fringe edge pairs connected for ``vclass``.

    Vehicles follow connections (directed); persons may walk either way along any edge that
    allows them and change edges at shared junctions.
    """
    edges = [e for e in net.getEdges() if e.getFunction() == "" and e.allows(vclass)]
    allowed = {e.getID() for e in edges}
    if directed:
        adj = {
            e.getID(): [o.getID() for o in e.getOutgoing() if o.getID() in allowed] for e in edges
        }
    else:
        at_node: dict[str, list[str]] = {}
        for e in edges:
            for n in (e.getFromNode(), e.getToNode()):
                at_node.setdefault(n.getID(), []).append(e.getID())
        adj = {
            e.getID(): at_node[e.getFromNode().getID()] + at_node[e.getToNode().getID()]
            for e in edges
        }
    fringe = [e.getID() for e in edges if e.is_fringe()]
    if len(fringe) < 2:
        fringe = [e.getID() for e in edges]
    fringe_set = set(fringe)
    pairs = []
    for origin in fringe:
        seen = {origin}
        queue = deque([origin])
        while queue:
            for nxt in adj[queue.popleft()]:
                if nxt not in seen:
                    seen.add(nxt)
                    queue.append(nxt)
        pairs += [(origin, d) for d in fringe if d != origin and d in seen and d in fringe_set]
    return pairs


def write_demand(net_file: str | Path, out_file: str | Path, config: DemandConfig) -> Path:
    """Write a SUMO route file with vTypes, vehicle trips and walking persons; return its path.

    Same net, config and seed give the same file byte for byte.
    """
    config.validate()
    net = sumolib.net.readNet(str(net_file), withPedestrianConnections=True)
    rng = np.random.default_rng(config.seed)
    root = etree.Element("routes")
    used = [name for name, share in config.vehicle_mix.items() if share > 0]
    for name in used:
        t = VEHICLE_TYPES[name]
        etree.SubElement(
            root,
            "vType",
            id=name,
            vClass=t.vclass,
            length=str(t.length),
            width=str(t.width),
            height=str(t.height),
            maxSpeed=str(t.max_speed),
            accel=str(t.accel),
            decel=str(t.decel),
            guiShape=t.gui_shape,
        )
    p = PEDESTRIAN_TYPE
    etree.SubElement(
        root,
        "vType",
        id="pedestrian",
        vClass="pedestrian",
        length=str(p.length),
        width=str(p.width),
        height=str(p.height),
        maxSpeed=str(p.max_speed),
    )
    entries: list[tuple[float, int, etree._Element]] = []
    if config.vehicles_per_hour > 0 and used:
        shares = np.array([config.vehicle_mix[n] for n in used], dtype=float)
        shares /= shares.sum()
        times = _arrivals(rng, config.vehicles_per_hour, config.begin, config.end)
        kinds = rng.choice(len(used), size=len(times), p=shares)
        od_by_type = {n: _od_pairs(net, VEHICLE_TYPES[n].vclass, True) for n in used}
        for k, (t, kind) in enumerate(zip(times, kinds, strict=True)):
            name = used[kind]
            ods = od_by_type[name]
            if not ods:
                raise HiyariError(f"{net_file}: no route between fringe edges for {name!r}")
            o, d = ods[rng.integers(len(ods))]
            el = etree.Element(
                "trip",
                id=f"veh{k}",
                type=name,
                depart=f"{t:.1f}",
                attrib={"from": o, "to": d, "departLane": "best", "departSpeed": "max"},
            )
            entries.append((float(t), 0, el))
    if config.persons_per_hour > 0:
        ods = _od_pairs(net, "pedestrian", False)
        if not ods:
            raise HiyariError(f"{net_file}: no walkable edges for persons")
        times = _arrivals(rng, config.persons_per_hour, config.begin, config.end)
        for k, t in enumerate(times):
            o, d = ods[rng.integers(len(ods))]
            el = etree.Element("person", id=f"ped{k}", type="pedestrian", depart=f"{t:.1f}")
            etree.SubElement(el, "walk", attrib={"from": o, "to": d})
            entries.append((float(t), 1, el))
    for _, _, el in sorted(entries, key=lambda e: (e[0], e[1], e[2].get("id"))):
        root.append(el)
    with atomic_path(out_file) as tmp:
        etree.ElementTree(root).write(
            str(tmp), pretty_print=True, xml_declaration=True, encoding="UTF-8"
        )
    return Path(out_file)
