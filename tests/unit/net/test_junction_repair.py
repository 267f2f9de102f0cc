"""Lanes netconvert cut to a point get a straight 0.1 m shape (hand-written net XML, no
SUMO): a short footway piece between two junctions at different heights, in the Helsinki
extract, became a lane whose two shape points coincide, and SUMO put a person walking onto
it at NaN."""

from __future__ import annotations

from lxml import etree

from hiyari.net.sumo.osm.junction_repair import straighten_collapsed


def test_a_lane_cut_to_a_point_gets_a_straight_shape_along_its_edge():
    root = etree.fromstring("""<net>
  <edge id="e" from="A" to="B"><lane id="e_0" index="0" shape="5.00,3.00,-0.76 5.00,3.00,-0.76"/></edge>
  <edge id="f" from="B" to="A"><lane id="f_0" index="0" shape="0.00,3.00 0.00,0.00"/></edge>
  <junction id="A" x="5.0" y="0.0"/><junction id="B" x="5.0" y="8.0"/>
</net>""")  # fmt: skip
    assert straighten_collapsed(root) == ["e_0"]
    shapes = {ln.get("id"): ln.get("shape") for ln in root.iter("lane")}
    # along A -> B (north), centred on the point, its height kept; the other lane untouched
    assert shapes == {"e_0": "5.00,2.95,-0.76 5.00,3.05,-0.76", "f_0": "0.00,3.00 0.00,0.00"}
