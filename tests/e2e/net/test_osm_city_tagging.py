"""What a real city extract brought out, on a small map written here: a closed-loop city run
whose ego route passes a road piece shorter than a metre. netconvert leaves such pieces
(0.2 m) between two junctions a few metres apart that it does not join, as a mapped crossing
or a footway meeting the street next to a junction makes them (89 of 637 car edges of the
Helsinki centre extract); the route's waypoint 1 m into every edge was off those pieces."""

from __future__ import annotations

from pathlib import Path

from runs import run_preset

from hiyari.bridge.loop.execute import RunOptions
from hiyari.bridge.openscenario.presets.scenarios import World
from hiyari.bridge.openscenario.presets.toml_file import parse_scenario
from hiyari.net.road.network import RoadNetwork
from hiyari.sumo_tools import run_sumo_tool


def _short_piece(folder: Path) -> Path:
    """A one-way street A -> B -> C -> D with side streets at B and C, 1 m apart."""
    nodes = folder / "s.nod.xml"
    nodes.write_text("""<nodes>
  <node id="A" x="-200" y="0"/><node id="B" x="0" y="0"/><node id="C" x="1" y="0"/>
  <node id="D" x="200" y="0"/><node id="N" x="0" y="150"/><node id="S" x="1" y="-150"/>
</nodes>""")  # fmt: skip
    edges = folder / "s.edg.xml"
    edges.write_text("""<edges>
  <edge id="AB" from="A" to="B" numLanes="1" speed="13.9"/>
  <edge id="BC" from="B" to="C" numLanes="1" speed="13.9"/>
  <edge id="CD" from="C" to="D" numLanes="1" speed="13.9"/>
  <edge id="BN" from="B" to="N" numLanes="1" speed="13.9"/>
  <edge id="SC" from="S" to="C" numLanes="1" speed="13.9"/>
</edges>""")  # fmt: skip
    net = folder / "s.net.xml"
    run_sumo_tool("netconvert", ["-n", str(nodes), "-e", str(edges), "-o", str(net)], "test net")
    return net


def test_city_run_whose_route_passes_a_piece_shorter_than_a_metre(tmp_path):
    net = _short_piece(tmp_path)
    assert RoadNetwork(net).sumo.getEdge("BC").getLength() < 1.0  # the junctions' shapes meet
    logical = parse_scenario(
        {"scenario": {"type": "city", "duration": 2.0, "step_length": 0.1},
         "parameters": {"warmup_s": 1.0, "vehicles_per_hour": 0, "persons_per_hour": 0}},
        "city.toml",
    )  # fmt: skip
    (cs,) = logical.expand()
    result = run_preset(cs, RunOptions(out_dir=tmp_path / "run"), world=World.of_net(net))
    assert result.sim_seconds > 0 and not result.collision
