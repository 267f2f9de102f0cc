"""Checks on SUMO input files before SUMO sees them, so errors name the file in one line."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from hiyari.errors import HiyariError


def check_xml(path: str | Path, root_tags: tuple[str, ...], what: str) -> etree._Element:
    """Parse ``path`` and check its root element; raise HiyariError naming the file otherwise.

    ``what`` names the role of the file ("network", "route file") in the message.
    """
    path = Path(path)
    if not path.is_file():
        raise HiyariError(f"{path}: {what} not found")
    try:
        root = etree.parse(str(path), etree.XMLParser(huge_tree=True)).getroot()
    except etree.XMLSyntaxError as exc:
        raise HiyariError(f"{path}: {what} is not well-formed XML: {exc.msg}") from None
    except OSError as exc:  # lxml reports undecodable bytes as a read error
        raise HiyariError(f"{path}: {what} cannot be read: {exc}") from None
    if root.tag not in root_tags:
        expected = " or ".join(f"<{t}>" for t in root_tags)
        raise HiyariError(
            f"{path}: not a SUMO {what} (root element <{root.tag}>, expected {expected})"
        )
    return root


def check_net(path: str | Path) -> etree._Element:
    """A SUMO network with at least one lane that vehicles may drive on."""
    root = check_xml(path, ("net",), "network")
    drivable = False
    for lane in root.iter("lane"):
        allow = lane.get("allow")
        if allow is not None and allow.split() and set(allow.split()) <= {"pedestrian"}:
            continue
        if lane.get("disallow") == "all":
            continue
        drivable = True
        break
    if not drivable:
        raise HiyariError(f"{path}: network has no drivable lanes")
    return root


def check_routes(path: str | Path) -> etree._Element:
    """A SUMO route / demand file (root <routes>)."""
    return check_xml(path, ("routes",), "route file")


#: Lane lengths (m) two nets may differ by and still be the same road (netconvert writes
#: two decimals; a re-import on another platform may round the last one differently).
SAME_LENGTH_TOLERANCE = 0.1


def _lanes_by_edge(root: etree._Element) -> dict[str, list[float]]:
    """Ordinary edge id -> its lanes' lengths (m), internal and pedestrian edges left out."""
    return {
        e.get("id", ""): [float(ln.get("length", "nan")) for ln in e.iter("lane")]
        for e in root.iter("edge")
        if e.get("function") is None
    }


def road_difference(net: str | Path, reference: str | Path) -> str | None:
    """How ``net`` differs from ``reference`` as a road, in words about ``net``: the first
    edge it has that the reference lacks ("is not in the reference") or lacks ("is
    missing"), or an edge whose lane count or lane lengths (beyond SAME_LENGTH_TOLERANCE m)
    differ; None when they have the same edges and lanes."""
    mine, theirs = _lanes_by_edge(check_net(net)), _lanes_by_edge(check_net(reference))
    only = sorted(set(mine) ^ set(theirs))
    if only:
        where = "is not in the reference" if only[0] in mine else "is missing"
        return f"edge {only[0]} {where}"
    for edge in sorted(mine):
        a, b = mine[edge], theirs[edge]
        if len(a) != len(b):
            return f"edge {edge} has {len(a)} lane(s), not {len(b)}"
        if any(not abs(x - y) <= SAME_LENGTH_TOLERANCE for x, y in zip(a, b, strict=True)):
            return f"edge {edge}'s lanes are {a} m long, not {b} m"
    return None
