"""Generate SUMO networks from plain XML (nodes, edges) with lxml and netconvert."""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.errors import HiyariError
from hiyari.sumo_tools import run_sumo_tool


@dataclass(frozen=True)
class IntersectionParams:
    """A four-leg intersection: arm length and lane width in metres, speed limit in m/s."""

    arm_length: float = 150.0
    lanes_per_direction: int = 1
    lane_width: float = 3.5
    sidewalk_width: float = 2.0
    speed_limit: float = 13.89
    traffic_light: bool = False
    crossings: bool = True

    def validate(self) -> None:
        if self.arm_length < 20 or self.lane_width < 2.0 or self.lanes_per_direction < 1:
            raise HiyariError(
                "intersection: arm length >= 20 m, lane width >= 2 m, >= 1 lane per direction"
            )


def _write_plain(folder: Path, nodes: list[dict], edges: list[dict]) -> tuple[Path, Path]:
    nod = etree.Element("nodes")
    for n in nodes:
        etree.SubElement(nod, "node", {k: str(v) for k, v in n.items()})
    edg = etree.Element("edges")
    for e in edges:
        etree.SubElement(edg, "edge", {k: str(v) for k, v in e.items()})
    np_, ep = folder / "plain.nod.xml", folder / "plain.edg.xml"
    etree.ElementTree(nod).write(str(np_), pretty_print=True)
    etree.ElementTree(edg).write(str(ep), pretty_print=True)
    return np_, ep


def build_intersection(out: str | Path, params: IntersectionParams | None = None) -> Path:
    """Write a four-leg intersection with sidewalks and crossings to ``out`` (.net.xml)."""
    p = params or IntersectionParams()
    p.validate()
    a = p.arm_length
    ends = {"n": (0, a), "e": (a, 0), "s": (0, -a), "w": (-a, 0)}
    ctype = "traffic_light" if p.traffic_light else "priority"
    nodes = [{"id": "C", "x": 0, "y": 0, "type": ctype}]
    nodes += [{"id": k, "x": x, "y": y, "type": "dead_end"} for k, (x, y) in ends.items()]
    edges = []
    for k in ends:
        common = {
            "numLanes": p.lanes_per_direction,
            "speed": p.speed_limit,
            "width": p.lane_width,
            "sidewalkWidth": p.sidewalk_width,
        }
        edges.append({"id": f"{k}_in", "from": k, "to": "C", **common})
        edges.append({"id": f"{k}_out", "from": "C", "to": k, **common})
    with tempfile.TemporaryDirectory(prefix="hiyari-net-") as tmp:
        nf, ef = _write_plain(Path(tmp), nodes, edges)
        with atomic_path(out) as target:
            args = [
                "-n",
                str(nf),
                "-e",
                str(ef),
                "-o",
                str(target),
                "--no-turnarounds",
                "true",
                "--sidewalks.guess",
                "true",
                "--walkingareas",
                "true",
            ]
            if p.crossings:
                args += ["--crossings.guess", "true"]
            run_sumo_tool("netconvert", args, "intersection")
    return Path(out)
