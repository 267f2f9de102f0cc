"""Seeded demand on any drivable network: vehicles and persons per hour.

Vehicles (per vehicle class) follow the net's lane connections that class may use. The
network is split into strongly connected components; traffic enters at the components no
other component leads into and leaves at those that lead nowhere, so every one-way stretch,
each direction of a dual carriageway and every separate network part gets its share:
- a trip goes from an entry edge to an exit edge reachable from it (a stretch of road without
  junctions is its own entry and exit: the vehicle drives it end to end);
- a closed part that nothing enters and nothing leaves (a loop, a town without dead ends)
  gets circulating vehicles: each is inserted on the road with a closed route through that
  part (a seeded random walk, closed by the shortest way back) repeated for the whole run,
  so it stays on the road.
Persons walk between the edges pedestrians may use (sidewalks, footpaths, walking areas,
crossings) that are connected for walking, preferring the network's fringe.

Arrivals are Poisson; the same net, config and seed give the same file byte for byte.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from lxml import etree
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.net.road.geometry import permissions
from hiyari.net.sumo.files import check_net
from hiyari.traffic.actor_class import ActorClass

#: Closed routes of circulating vehicles are walked until at least this long, m; the route
#: then repeats (SUMO ``repeat``) for the rest of the run.
LOOP_LENGTH = 3000.0


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
    """Poisson arrivals of vehicles and persons. Rates per hour, times in seconds.

    ``crossings``: the persons walk across these pedestrian crossings (SUMO crossing edge ids
    such as ``:J_c0``), each person one of them drawn uniformly, in either direction, from
    CROSSING_APPROACH m before it on one sidewalk to as far beyond it on the other; where a
    junction has several crossings, SUMO's pedestrian router may take another of them if it
    is as short (a mapped mid-block crossing is two, one each side of its node) (empty:
    persons walk between the walkable fringes)."""

    vehicles_per_hour: float = 600.0
    persons_per_hour: float = 300.0
    begin: float = 0.0
    end: float = 3600.0
    seed: int = 1
    vehicle_mix: dict[str, float] = field(default_factory=lambda: {"car": 1.0})
    crossings: tuple[str, ...] = ()

    def validate(self) -> None:
        """Raise HiyariError for impossible rates, times or unknown vehicle types."""
        for name, value in (("vehicles per hour", self.vehicles_per_hour),
                            ("persons per hour", self.persons_per_hour),
                            ("begin", self.begin), ("end", self.end)):  # fmt: skip
            if not math.isfinite(value):
                raise HiyariError(f"demand {name} must be a finite number, got {value}")
        if self.vehicles_per_hour < 0 or self.persons_per_hour < 0:
            raise HiyariError("demand rates must be >= 0 per hour")
        if self.end <= self.begin:
            raise HiyariError(f"demand end {self.end} s must be after begin {self.begin} s")
        for name, share in self.vehicle_mix.items():
            if name not in VEHICLE_TYPES:
                known = ", ".join(VEHICLE_TYPES)
                raise HiyariError(f"unknown vehicle type {name!r} in the mix (known: {known})")
            if not share >= 0:
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


@dataclass(frozen=True)
class _Net:
    """What demand needs of a SUMO net: normal edges, lanes, connections."""

    edges: list[str]  # normal edges in file order
    function: dict[str, str]  # every edge -> "" / internal / crossing / walkingarea
    lane_allowed: dict[str, frozenset[str]]  # lane id -> vehicle classes
    edge_lanes: dict[str, list[str]]  # every edge -> its lane ids
    nodes: dict[str, tuple[str, str]]  # normal edges -> (from node, to node)
    edge_length: dict[str, float]  # normal edges, m (first lane)
    edge_speed: dict[str, float]  # normal edges, fastest lane, m/s
    connections: list[tuple[str, str, str, str, str]]  # from, fromLane, to, toLane, dir
    crossing_edges: dict[str, list[str]]  # crossing edge -> the road edges it crosses


def _read_net(net_file: str | Path) -> _Net:
    root = check_net(net_file)
    try:
        edges, function, allowed, edge_lanes, nodes, length, speed = [], {}, {}, {}, {}, {}, {}
        crossed = {}
        for e in root.iter("edge"):
            eid, fn = e.get("id"), e.get("function", "")
            function[eid] = fn
            if fn == "crossing":
                crossed[eid] = e.get("crossingEdges", "").split()
            lanes = e.findall("lane")
            for ln in lanes:
                allowed[ln.get("id")] = permissions(ln.get("allow"), ln.get("disallow"))
            edge_lanes[eid] = [ln.get("id") for ln in lanes]
            if fn == "" and lanes:
                edges.append(eid)
                nodes[eid] = (e.get("from"), e.get("to"))
                length[eid] = float(lanes[0].get("length"))
                speed[eid] = max(float(ln.get("speed")) for ln in lanes)
        connections = [
            (c.get("from"), c.get("fromLane"), c.get("to"), c.get("toLane"), c.get("dir", ""))
            for c in root.iter("connection")
        ]
    except (TypeError, ValueError) as exc:
        raise HiyariError(f"{net_file}: network has an unreadable edge or lane ({exc})") from None
    return _Net(edges, function, allowed, edge_lanes, nodes, length, speed, connections, crossed)


def _allows(net: _Net, edge: str, lane_index: str | None, vclass: str) -> bool:
    return vclass in net.lane_allowed.get(f"{edge}_{lane_index}", frozenset())


def _open_to(net: _Net, edge: str, vclass: str) -> bool:
    return any(vclass in net.lane_allowed[ln] for ln in net.edge_lanes[edge])


@dataclass(frozen=True)
class _Graph:
    """Directed edge graph of one vehicle class, with its strongly connected components."""

    edges: list[str]
    succ: list[list[int]]
    matrix: coo_matrix  # adjacency, edge index -> edge index
    comp: np.ndarray  # component label per edge
    comp_in: np.ndarray  # per component: edges enter it from other components
    comp_out: np.ndarray
    comp_cycle: np.ndarray  # per component: has a cycle (more than one edge or a self-loop)


def _vehicle_graph(net: _Net, vclass: str) -> _Graph:
    edges = [e for e in net.edges if _open_to(net, e, vclass)]
    index = {e: k for k, e in enumerate(edges)}
    pairs = sorted(
        {
            (index[f], index[t])
            for f, fl, t, tl, _ in net.connections
            if f in index and t in index and _allows(net, f, fl, vclass)
            and _allows(net, t, tl, vclass)
        }
    )  # fmt: skip
    n = len(edges)
    src = np.array([p[0] for p in pairs], dtype=np.int64)
    dst = np.array([p[1] for p in pairs], dtype=np.int64)
    matrix = coo_matrix((np.ones(len(pairs)), (src, dst)), shape=(n, n))
    ncomp, comp = connected_components(matrix, directed=True, connection="strong")
    across = comp[src] != comp[dst]
    comp_in = np.bincount(comp[dst[across]], minlength=ncomp) > 0
    comp_out = np.bincount(comp[src[across]], minlength=ncomp) > 0
    sizes = np.bincount(comp, minlength=ncomp)
    cycle = sizes > 1
    cycle[comp[src[src == dst]]] = True
    succ: list[list[int]] = [[] for _ in range(n)]
    for a, b in pairs:
        succ[a].append(b)
    return _Graph(edges, succ, matrix.tocsr(), comp, comp_in, comp_out, cycle)


def _trip_pairs(g: _Graph) -> list[tuple[int, int]]:
    """(origin, destination) edge indices from entry components to reachable exits."""
    closed = ~g.comp_in & ~g.comp_out & g.comp_cycle  # circulating parts, no trips
    entry = [k for k in range(len(g.edges)) if not g.comp_in[g.comp[k]] and not closed[g.comp[k]]]
    exits = {k for k in range(len(g.edges)) if not g.comp_out[g.comp[k]] and not closed[g.comp[k]]}
    pairs = []
    for origin in entry:
        seen = breadth_first_order(g.matrix, origin, directed=True, return_predecessors=False)
        own = g.comp_out[g.comp[origin]] or g.comp_cycle[g.comp[origin]]
        pairs += [(origin, d) for d in sorted(exits.intersection(seen.tolist()))
                  if d != origin or not own]  # fmt: skip
    return pairs


def _way_back(g: _Graph, start: int, end: int) -> list[int]:
    """Shortest edge sequence after ``start`` up to and including ``end`` (same component)."""
    prev = {start: -1}
    queue = deque([start])
    while queue:
        k = queue.popleft()
        for nxt in g.succ[k]:
            if nxt not in prev and g.comp[nxt] == g.comp[start]:
                prev[nxt] = k
                queue.append(nxt)
    path, k = [], end
    while k != start:
        path.append(k)
        k = prev[k]
    return path[::-1]


def _loop_route(g: _Graph, net: _Net, start: int, rng: np.random.Generator) -> list[str]:
    """A closed route from ``start`` within its component: a random walk of at least
    ``LOOP_LENGTH`` (or until it returns to ``start``), then the shortest way back."""
    route, length = [start], net.edge_length[g.edges[start]]
    while length < LOOP_LENGTH:
        options = [k for k in g.succ[route[-1]] if g.comp[k] == g.comp[start]]
        k = options[int(rng.integers(len(options)))]
        if k == start:
            break
        route.append(k)
        length += net.edge_length[g.edges[k]]
    else:
        route += [k for k in _way_back(g, route[-1], start) if k != start]
    return [g.edges[k] for k in route]


def _vehicle_entries(net: _Net, net_file: str | Path, config: DemandConfig,
                     rng: np.random.Generator) -> list[tuple[float, int, etree._Element]]:  # fmt: skip
    used = [name for name, share in config.vehicle_mix.items() if share > 0]
    if config.vehicles_per_hour <= 0 or not used:
        return []
    shares = np.array([config.vehicle_mix[n] for n in used], dtype=float)
    times = _arrivals(rng, config.vehicles_per_hour, config.begin, config.end)
    kinds = rng.choice(len(used), size=len(times), p=shares / shares.sum())
    graphs = {n: _vehicle_graph(net, VEHICLE_TYPES[n].vclass) for n in used}
    trips = {n: _trip_pairs(g) for n, g in graphs.items()}
    loops = {
        n: [k for k in range(len(g.edges)) if not (g.comp_in | g.comp_out)[g.comp[k]]
            and g.comp_cycle[g.comp[k]]]
        for n, g in graphs.items()
    }  # fmt: skip
    entries = []
    for k, (t, kind) in enumerate(zip(times, kinds, strict=True)):
        name = used[kind]
        g, pairs, circ = graphs[name], trips[name], loops[name]
        if not pairs and not circ:
            raise HiyariError(f"{net_file}: no lane of the network is open to {name!r}")
        pick = int(rng.integers(len(pairs) + len(circ)))
        attrib = {"departLane": "best", "departSpeed": "max"}
        if pick < len(pairs):
            o, d = pairs[pick]
            attrib |= {"from": g.edges[o], "to": g.edges[d]}
            el = etree.Element("trip", id=f"veh{k}", type=name, depart=f"{t:.1f}", attrib=attrib)
        else:
            route = _loop_route(g, net, circ[pick - len(pairs)], rng)
            speed = min(VEHICLE_TYPES[name].max_speed, max(net.edge_speed[e] for e in route))
            laps = (config.end - t) * speed / sum(net.edge_length[e] for e in route)
            el = etree.Element("vehicle", id=f"veh{k}", type=name, depart=f"{t:.1f}",
                               attrib=attrib)  # fmt: skip
            etree.SubElement(el, "route", edges=" ".join(route), repeat=str(math.ceil(laps)))
        entries.append((float(t), 0, el))
    return entries


def _walk_pairs(net: _Net) -> list[tuple[str, str]]:
    """(from, to) normal edges connected for walking; fringe edges where a part has two."""
    walkable = [e for e in net.function if _open_to(net, e, "pedestrian")]
    index = {e: k for k, e in enumerate(walkable)}
    has_areas = any(net.function[e] == "walkingarea" for e in walkable)
    # lane to lane: a street's car lanes lead on across a junction where its sidewalks may not
    # (no crossing over a fast road), and persons only walk the lanes that allow them
    links = [(f, t) for f, fl, t, tl, _ in net.connections
             if f in index and t in index and _allows(net, f, fl, "pedestrian")
             and _allows(net, t, tl, "pedestrian")]  # fmt: skip
    if not has_areas:  # no walking areas: pedestrians change edges at shared nodes
        links = _shared_node_links(net, walkable)
    n = len(walkable)
    src = np.array([index[f] for f, _ in links], dtype=np.int64)
    dst = np.array([index[t] for _, t in links], dtype=np.int64)
    _, comp = connected_components(coo_matrix((np.ones(len(links)), (src, dst)), shape=(n, n)),
                                   directed=False)  # fmt: skip
    normal = [e for e in walkable if net.function[e] == ""]
    turns_in: dict[str, int] = {}
    turns_out: dict[str, int] = {}
    for f, _, t, _, d in net.connections:
        if d != "t" and net.function.get(f) == "" and net.function.get(t) == "":
            turns_out[f] = turns_out.get(f, 0) + 1
            turns_in[t] = turns_in.get(t, 0) + 1
    pairs = []
    for c in np.unique(comp[[index[e] for e in normal]]) if normal else []:
        members = [e for e in normal if comp[index[e]] == c]
        fringe = [e for e in members if not turns_in.get(e) or not turns_out.get(e)]
        ends = fringe if len(fringe) >= 2 else members
        pairs += [(o, d) for o in ends for d in ends if d != o or len(ends) == 1]
    return pairs


def _shared_node_links(net: _Net, walkable: list[str]) -> list[tuple[str, str]]:
    """Walkable normal edges linked where they share a node (nets without walking areas)."""
    at_node: dict[str, list[str]] = {}
    for e in walkable:
        for node in net.nodes.get(e, ()):
            at_node.setdefault(node, []).append(e)
    return [(a, b) for group in at_node.values() for a in group for b in group if a != b]


def write_demand(net_file: str | Path, out_file: str | Path, config: DemandConfig) -> Path:
    """Write a SUMO route file with vTypes, vehicles and walking persons; return its path.

    HiyariError (one line naming the file) for an unreadable net, impossible settings, or a
    net without lanes for the requested vehicle types or persons. Same net, config and seed
    give the same file byte for byte.
    """
    config.validate()
    net = _read_net(net_file)
    rng = np.random.default_rng(config.seed)
    root = etree.Element("routes")
    for name in [n for n, share in config.vehicle_mix.items() if share > 0]:
        _vtype(root, name, VEHICLE_TYPES[name])
    _vtype(root, "pedestrian", PEDESTRIAN_TYPE)
    entries = _vehicle_entries(net, net_file, config, rng)
    if config.crossings:
        entries += _crossing_persons(net, net_file, config, rng)
    elif config.persons_per_hour > 0:
        pairs = _walk_pairs(net)
        if not pairs:
            raise HiyariError(f"{net_file}: no walkable edges for persons")
        times = _arrivals(rng, config.persons_per_hour, config.begin, config.end)
        for k, t in enumerate(times):
            o, d = pairs[rng.integers(len(pairs))]
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


#: Metres a crossing walker (DemandConfig.crossings) walks on the sidewalk before and after
#: its crossing, at most a quarter of the sidewalk's length: short, so that the crossing is
#: the pedestrian router's shortest way even where another crossing is a short block away
#: (20 m sent walkers over a mid-block zebra 41 m from their signalised crossing).
CROSSING_APPROACH = 10.0


def crossing_ids(net_file: str | Path, walkable: bool = False) -> list[str]:
    """The pedestrian crossings of a SUMO net: their edge ids (``:J_c0``), in file order;
    ``walkable``: only those with a sidewalk at both ends (crossing walkers can use them)."""
    net = _read_net(net_file)
    found = [e for e, fn in net.function.items() if fn == "crossing"]
    return [c for c in found if not walkable or _sides_or_none(net, net_file, c) is not None]


def check_crossings(net_file: str | Path, crossings: Sequence[str]) -> None:
    """HiyariError (one line naming the file and the first bad id) unless every id of
    ``crossings`` is a pedestrian crossing of the net with a sidewalk at both ends."""
    _checked_sides(_read_net(net_file), net_file, crossings)


def _checked_sides(
    net: _Net, net_file: str | Path, crossings: Sequence[str]
) -> list[tuple[tuple[str, float], tuple[str, float]]]:
    """``_crossing_sides`` of every crossing, each id checked first."""
    known = [e for e, fn in net.function.items() if fn == "crossing"]
    for c in crossings:
        if c not in known:
            some = ", ".join(known[:3]) + (", ..." if len(known) > 3 else "")
            raise HiyariError(f"{net_file}: no pedestrian crossing {c!r} (the net has "
                              f"{len(known)}{': ' + some if known else ''})")  # fmt: skip
    return [_crossing_sides(net, net_file, c) for c in crossings]


def _sides_or_none(
    net: _Net, net_file: str | Path, crossing: str
) -> tuple[tuple[str, float], tuple[str, float]] | None:
    """``_crossing_sides``, or None when the crossing has no sidewalk at both ends."""
    try:
        return _crossing_sides(net, net_file, crossing)
    except HiyariError:
        return None


def _crossing_persons(
    net: _Net, net_file: str | Path, config: DemandConfig, rng: np.random.Generator
) -> list[tuple[float, int, etree._Element]]:
    """The persons of ``config.crossings`` (see DemandConfig), as (depart, 1, element)."""
    sides = _checked_sides(net, net_file, config.crossings)
    out = []
    for k, t in enumerate(_arrivals(rng, config.persons_per_hour, config.begin, config.end)):
        pick = int(rng.integers(2 * len(sides)))
        (a, a_pos), (b, b_pos) = sides[pick // 2][:: 1 - 2 * (pick % 2)]
        el = etree.Element("person", id=f"ped{k}", type="pedestrian", depart=f"{t:.1f}",
                           departPos=f"{a_pos:.2f}")  # fmt: skip
        etree.SubElement(el, "walk", attrib={"from": a, "to": b, "arrivalPos": f"{b_pos:.2f}"})
        out.append((float(t), 1, el))
    return out


def _crossing_sides(
    net: _Net, net_file: str | Path, crossing: str
) -> tuple[tuple[str, float], tuple[str, float]]:
    """The two sidewalk ends of ``crossing``: per end a walkable normal edge reaching the
    walking area there (one of the crossed roads' where it can) and the position on it
    CROSSING_APPROACH m (at most a quarter of the edge) from the crossing's junction (m from
    the edge's start)."""
    junction = crossing[1:].rsplit("_c", 1)[0]
    into = [f for f, _, t, _, _ in net.connections if t == crossing]
    out_of = [t for f, _, t, _, _ in net.connections if f == crossing]
    crossed = set(net.crossing_edges.get(crossing, ()))
    ends = []
    for area in into[:1] + out_of[:1]:  # the walking areas before and after it
        touching = [x for f, _, t, _, _ in net.connections for x in (f, t)
                    if area in (f, t) and net.function.get(x) == "" and x != area
                    and _open_to(net, x, "pedestrian")]  # fmt: skip
        touching = sorted(dict.fromkeys(touching), key=lambda e: (e not in crossed, e))
        if not touching:
            break
        edge = touching[0]
        length = net.edge_length[edge]
        at_start = net.nodes[edge][0] == junction
        approach = min(CROSSING_APPROACH, 0.25 * length)
        pos = approach if at_start else length - approach
        ends.append((edge, pos))
    if len(ends) < 2 or ends[0][0] == ends[1][0]:
        raise HiyariError(f"{net_file}: crossing {crossing} has no sidewalk at both ends")
    return ends[0], ends[1]


def _vtype(root: etree._Element, name: str, t: VehicleType) -> None:
    attrs = {"id": name, "vClass": t.vclass, "length": str(t.length), "width": str(t.width),
             "height": str(t.height), "maxSpeed": str(t.max_speed)}  # fmt: skip
    if name != "pedestrian":
        attrs |= {"accel": str(t.accel), "decel": str(t.decel), "guiShape": t.gui_shape}
    etree.SubElement(root, "vType", attrs)
