"""Write SUMO plain XML (nodes, edges, connections) with lxml and turn it into a net.

Nodes and edges are plain dicts of SUMO attributes. An edge dict may also carry ``lanes``
(a list of per-lane attribute dicts, each with ``index``) and ``params`` (generic parameters
that netconvert copies into the net, such as the ``hiyari:*`` roadside keys read by
``hiyari.net.road.geometry``). Shapes are (n, 2) or (n, 3) arrays in metres.
"""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from lxml import etree

from hiyari.atomic import atomic_path
from hiyari.sumo_tools import run_sumo_tool


def format_shape(points: np.ndarray) -> str:
    """SUMO shape string 'x,y[,z] x,y[,z] ...' with millimetre precision."""
    return " ".join(",".join(f"{v:.3f}" for v in p) for p in np.asarray(points, dtype=np.float64))


def _attrs(d: dict) -> dict[str, str]:
    out = {}
    for k, v in d.items():
        if k in ("lanes", "params") or v is None:
            continue
        out[k] = format_shape(v) if isinstance(v, np.ndarray) else str(v)
    return out


def write_plain(
    folder: Path,
    nodes: Sequence[dict],
    edges: Sequence[dict],
    connections: Sequence[dict] = (),
) -> list[str]:
    """Write plain XML files into ``folder``; return the netconvert input arguments."""
    nod = etree.Element("nodes")
    for n in nodes:
        etree.SubElement(nod, "node", _attrs(n))
    edg = etree.Element("edges")
    for e in edges:
        el = etree.SubElement(edg, "edge", _attrs(e))
        for lane in e.get("lanes", ()):
            etree.SubElement(el, "lane", _attrs(lane))
        for key, value in e.get("params", {}).items():
            etree.SubElement(el, "param", key=key, value=str(value))
    files = {"-n": (folder / "plain.nod.xml", nod), "-e": (folder / "plain.edg.xml", edg)}
    if connections:
        con = etree.Element("connections")
        for c in connections:
            etree.SubElement(con, "connection", _attrs(c))
        files["-x"] = (folder / "plain.con.xml", con)
    args: list[str] = []
    for flag, (path, root) in files.items():
        etree.ElementTree(root).write(str(path), pretty_print=True)
        args += [flag, str(path)]
    return args


def build_net(
    out: str | Path,
    nodes: Sequence[dict],
    edges: Sequence[dict],
    options: Sequence[str],
    what: str,
    connections: Sequence[dict] = (),
) -> Path:
    """Run netconvert on the plain XML and write ``out`` atomically; return its path.

    ``options`` are extra netconvert options; ``what`` names the network in error messages.
    """
    with tempfile.TemporaryDirectory(prefix="hiyari-net-") as tmp:
        inputs = write_plain(Path(tmp), nodes, edges, connections)
        with atomic_path(out) as target:
            run_sumo_tool("netconvert", [*inputs, "-o", str(target), *options], what)
    return Path(out)
