"""Plain-XML layout of the generated expressway: nodes, edges with custom lane shapes, connections.

Every lane shape is computed here (not by netconvert) so that each lane carries its own
heights: longitudinal gradient plus the cross slope of its carriageway. SUMO then places
vehicles at those heights, and the 3D scene built from the net matches them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from hiyari.net.sumo.alignment import Alignment, Element

if TYPE_CHECKING:
    from hiyari.net.sumo.build import ExpresswayParams

#: Clear distance (m) beyond the outer shoulder within which a ramp is too close to the main
#: line for a guard rail between them: that stretch ("nose" / "gore") gets no outer rail.
NOSE_CLEARANCE = 1.0


def make_alignment(p: ExpresswayParams) -> Alignment:
    """Straight - clothoid - arc - clothoid - straight (or one straight without a curve)."""
    if p.curve_length <= 0:
        return Alignment.from_elements([Element(p.length, 0.0, 0.0)])
    k = (1.0 if p.curve_left else -1.0) / p.curve_radius
    t = p.transition_length
    rest = p.length - p.curve_start - 2 * t - p.curve_length
    elements = [
        Element(p.curve_start, 0.0, 0.0),
        Element(t, 0.0, k),
        Element(p.curve_length, k, k),
        Element(t, k, 0.0),
        Element(rest, 0.0, 0.0),
    ]
    return Alignment.from_elements([e for e in elements if e.length > 0])


class _CrossSection:
    """Heights of the road surface: gradient along, cross slope / superelevation across."""

    def __init__(self, p: ExpresswayParams, alignment: Alignment) -> None:
        self.p = p
        self.alignment = alignment
        self.k_arc = 1.0 / p.curve_radius if p.curve_length > 0 else 0.0

    def z(self, s: np.ndarray, lateral: np.ndarray | float) -> np.ndarray:
        """Surface height (m) at stations ``s`` and ``lateral`` metres left of the alignment."""
        p = self.p
        y = np.broadcast_to(np.asarray(lateral, dtype=np.float64), np.shape(s))
        if self.k_arc > 0:
            bank = np.clip(np.abs(self.alignment.curvature_at(s)) / self.k_arc, 0.0, 1.0)
        else:
            bank = np.zeros(np.shape(s))
        side = 1.0 if p.curve_left else -1.0
        crown = -p.cross_slope * np.abs(y)
        banked = -p.superelevation * side * y
        return p.gradient * np.asarray(s) + (1 - bank) * crown + bank * banked


def _shape(
    a: Alignment,
    xs: _CrossSection,
    s: np.ndarray,
    lateral: np.ndarray | float,
    z_lateral: np.ndarray | None = None,
) -> np.ndarray:
    """(n, 3) points ``lateral`` m left of the alignment; heights at ``z_lateral`` if given."""
    lat = np.broadcast_to(np.asarray(lateral, dtype=np.float64), s.shape)
    zl = lat if z_lateral is None else z_lateral
    return np.column_stack([a.point(s, lat), xs.z(s, zl)])


def expressway_plain(p: ExpresswayParams) -> tuple[list[dict], list[dict], list[dict]]:
    """Nodes, edges and connections of the expressway described by ``p``."""
    a = make_alignment(p)
    xs = _CrossSection(p, a)
    n, w, half_median = p.lanes, p.lane_width, p.median_width / 2
    step = p.shape_step
    nose = 0.0
    if p.on_ramp or p.off_ramp:
        clearance = p.shoulder_right + NOSE_CLEARANCE
        nose = p.ramp_length * min(0.9, np.sqrt(clearance / p.ramp_offset))

    # (name, start station, end station, lanes, outer roadside (shoulder + rail))
    sections: list[tuple[str, float, float, int, bool]] = []
    cur = 0.0
    if p.on_ramp:
        sections += [
            ("east_in", 0.0, p.merge_station - nose, n, True),
            ("east_nose", p.merge_station - nose, p.merge_station, n, False),
            ("east_merge", p.merge_station, p.merge_station + p.accel_length, n + 1, True),
        ]
        cur = p.merge_station + p.accel_length
    if p.off_ramp:
        d0, d1 = p.diverge_station - p.decel_length, p.diverge_station
        sections += [
            ("east_mid" if p.on_ramp else "east_in", cur, d0, n, True),
            ("east_diverge", d0, d1, n + 1, True),
            ("east_gore", d1, d1 + nose, n, False),
            ("east_out", d1 + nose, p.length, n, True),
        ]
    else:
        sections.append(("east_out" if p.on_ramp else "east", cur, p.length, n, True))

    def roadside(outer: bool, left: float, right: float) -> dict[str, str]:
        rails = ["left"] + (["right"] if outer else [])
        params = {
            "hiyari:shoulder_left": f"{left:g}",
            "hiyari:shoulder_right": f"{right if outer else 0.0:g}",
        }
        params["hiyari:barrier"] = " ".join(rails) if p.guard_rails else "none"
        return params

    def node(
        node_id: str,
        s: float,
        lateral: float,
        kind: str = "priority",
        z_lateral: float | None = None,
    ) -> dict:
        zl = None if z_lateral is None else np.array([z_lateral])
        pt = _shape(a, xs, np.array([s]), lateral, zl)[0]
        return {"id": node_id, "x": pt[0], "y": pt[1], "z": pt[2], "type": kind}

    nodes = [node(f"e{k}", sec[1], -half_median) for k, sec in enumerate(sections)]
    nodes.append(node(f"e{len(sections)}", p.length, -half_median))
    nodes[0]["type"] = nodes[-1]["type"] = "dead_end"
    edges = []
    for k, (name, s0, s1, lanes, outer) in enumerate(sections):
        st = a.stations(s0, s1, step)
        lane_dicts = []
        for i in range(lanes):
            y = -(half_median + (lanes - i - 0.5) * w)
            lane_dicts.append({"index": i, "shape": _shape(a, xs, st, y), "width": w})
        edges.append(
            {
                "id": name,
                "from": f"e{k}",
                "to": f"e{k + 1}",
                "numLanes": lanes,
                "speed": p.speed_limit,
                "width": w,
                "spreadType": "right",
                "shape": _shape(a, xs, st, -half_median),
                "lanes": lane_dicts,
                "params": roadside(outer, p.shoulder_left, p.shoulder_right),
            }
        )
    # Westbound: one edge from the far end back to station 0, left of the alignment.
    st = a.stations(0.0, p.length, step)[::-1]
    nodes += [
        node("w0", p.length, half_median, "dead_end"),
        node("w1", 0.0, half_median, "dead_end"),
    ]
    edges.append(
        {
            "id": "west",
            "from": "w0",
            "to": "w1",
            "numLanes": n,
            "speed": p.speed_limit,
            "width": w,
            "spreadType": "right",
            "shape": _shape(a, xs, st, half_median),
            "lanes": [
                {
                    "index": i,
                    "shape": _shape(a, xs, st, half_median + (n - i - 0.5) * w),
                    "width": w,
                }
                for i in range(n)
            ],
            "params": roadside(True, p.shoulder_left, p.shoulder_right),
        }
    )
    names = [sec[0] for sec in sections]
    connections = []
    for upper, lower in zip(sections[:-1], sections[1:], strict=True):
        up, n_up, down, n_down = upper[0], upper[3], lower[0], lower[3]
        if n_down == n_up + 1:  # a lane is added on the right: through lanes shift up
            pairs = [(i, i + 1) for i in range(n_up)]
        elif n_down == n_up - 1:  # the right lane ends (merge) or leaves (diverge)
            pairs = [(i + 1, i) for i in range(n_down)]
        else:
            pairs = [(i, i) for i in range(n_up)]
        connections += [{"from": up, "to": down, "fromLane": i, "toLane": j} for i, j in pairs]

    y_extra = -(half_median + (n + 0.5) * w)  # centre of an acceleration / deceleration lane
    ramp_params = {"hiyari:shoulder_left": "0", "hiyari:shoulder_right": f"{p.shoulder_left:g}"}
    ramp_params["hiyari:barrier"] = "right" if p.guard_rails else "none"
    if p.on_ramp:
        s0, s1 = p.merge_station - p.ramp_length, p.merge_station
        st = a.stations(s0, s1, step, dense=np.array([s0, s1]))
        u = (st - s0) / p.ramp_length
        y = y_extra - p.ramp_offset * (1 - u) ** 2
        z_y = np.maximum(y, y_extra)
        nodes.append(node("onramp_start", s0, y[0] + w / 2, "dead_end", z_y[0]))
        k = names.index("east_merge")
        edges.append(
            _ramp_edge("onramp", "onramp_start", f"e{k}", a, xs, st, y, z_y, p, ramp_params)
        )
        connections.append({"from": "onramp", "to": "east_merge", "fromLane": 0, "toLane": 0})
    if p.off_ramp:
        s0, s1 = p.diverge_station, p.diverge_station + p.ramp_length
        st = a.stations(s0, s1, step, dense=np.array([s0, s1]))
        u = (st - s0) / p.ramp_length
        y = y_extra - p.ramp_offset * u**2
        z_y = np.maximum(y, y_extra)
        nodes.append(node("offramp_end", s1, y[-1] + w / 2, "dead_end", z_y[-1]))
        k = names.index("east_gore")
        edges.append(
            _ramp_edge("offramp", f"e{k}", "offramp_end", a, xs, st, y, z_y, p, ramp_params)
        )
        connections.append({"from": "east_diverge", "to": "offramp", "fromLane": 0, "toLane": 0})
    return nodes, edges, connections


def _ramp_edge(
    name: str,
    start: str,
    end: str,
    a: Alignment,
    xs: _CrossSection,
    st: np.ndarray,
    y: np.ndarray,
    z_y: np.ndarray,
    p: ExpresswayParams,
    params: dict[str, str],
) -> dict:
    """One-lane ramp edge along stations ``st`` at lateral offsets ``y``.

    Heights are the carriageway surface's at offsets ``z_y``: further out than the
    acceleration / deceleration lane a ramp keeps that lane's centre height (level across).
    """
    w = p.lane_width
    return {
        "id": name,
        "from": start,
        "to": end,
        "numLanes": 1,
        "speed": p.ramp_speed,
        "width": w,
        "spreadType": "right",
        "shape": _shape(a, xs, st, y + w / 2, z_y),
        "lanes": [{"index": 0, "shape": _shape(a, xs, st, y, z_y), "width": w}],
        "params": dict(params),
    }
