"""The difference between a net's links at a direct junction and the file's laneLinks, on a
hand-written net (no netconvert): what is missing, what is extra, which way each link runs."""

from __future__ import annotations

from lxml import etree

from hiyari.net.sumo.direct_junctions import compare_links, direct_junctions, write_connections

XODR = """<OpenDRIVE>
  <junction id="5" type="direct">
    <connection id="0" incomingRoad="1" linkedRoad="2" contactPoint="start">
      <laneLink from="1" to="1"/><laneLink from="-1" to="-1"/>
    </connection>
    <connection id="1" incomingRoad="1" linkedRoad="3" contactPoint="start">
      <laneLink from="-2" to="-1"/><laneLink from="-1" to="1"/>
    </connection>
  </junction>
  <junction id="6"><connection id="0" incomingRoad="1" connectingRoad="9"/></junction>
</OpenDRIVE>"""

# Road 1 (lanes 1 | -1 -2) ends at node 5; roads 2 (1 | -1) and 3 (-1) start there. The net
# lacks 2_0 -> 1_0 (road 2 lane 1 back into road 1) and has a turn 2_0 -> -3_0 of its own.
NET = """<net>
  <edge id="-1" from="a" to="5"><lane id="-1_0" index="0"><param key="origId" value="1_-2"/>
    </lane><lane id="-1_1" index="1"><param key="origId" value="1_-1"/></lane></edge>
  <edge id="1" from="5" to="a"><lane id="1_0" index="0"><param key="origId" value="1_1"/></lane>
  </edge>
  <edge id="-2" from="5" to="b"><lane id="-2_0" index="0"><param key="origId" value="2_-1"/>
  </lane></edge>
  <edge id="2" from="b" to="5"><lane id="2_0" index="0"><param key="origId" value="2_1"/></lane>
  </edge>
  <edge id="-3" from="5" to="c"><lane id="-3_0" index="0"><param key="origId" value="3_-1"/>
  </lane></edge>
  <edge id=":5_0" function="internal"><lane id=":5_0_0" index="0"/></edge>
  <connection from="-1" to="-2" fromLane="1" toLane="0" via=":5_0_0"/>
  <connection from="-1" to="-3" fromLane="0" toLane="0" via=":5_1_0"/>
  <connection from="2" to="-3" fromLane="0" toLane="0" via=":5_2_0"/>
  <connection from=":5_0" to="-2" fromLane="0" toLane="0"/>
</net>"""


def test_missing_and_extra_links_in_driving_direction(tmp_path):
    junctions = direct_junctions(etree.fromstring(XODR))
    assert [j.id for j in junctions] == ["5"]  # junction 6 is not direct
    (tmp_path / "n.net.xml").write_text(NET)
    patch = compare_links(tmp_path / "n.net.xml", junctions)
    # road 1 lane 1 enters road 1 from road 2 (left lane, against s): 2_0 -> 1_0
    assert patch.missing == (("2_0", "1_0"),)
    assert patch.extra == (("2_0", "-3_0"),)
    assert patch.unusable == ()  # laneLink -1 -> 1 names road 3 lane 1, not in the net: skipped
    con = etree.parse(str(write_connections(patch, tmp_path / "p.con.xml"))).getroot()
    assert [(c.tag, dict(c.attrib)) for c in con] == [
        ("delete", {"from": "2", "to": "-3", "fromLane": "0", "toLane": "0"}),
        # every link of the file, not only the missing one: netconvert builds only the listed
        # links of the edges a connection file names
        ("connection", {"from": "-1", "to": "-3", "fromLane": "0", "toLane": "0"}),
        ("connection", {"from": "-1", "to": "-2", "fromLane": "1", "toLane": "0"}),
        ("connection", {"from": "2", "to": "1", "fromLane": "0", "toLane": "0"}),
    ]


def test_links_whose_lanes_point_the_same_way_are_named(tmp_path):
    # road 1 lane 1 and road 2 lane -1 both leave node 5: no way to drive from one to the other
    xodr = XODR.replace('<laneLink from="1" to="1"/>', '<laneLink from="1" to="-1"/>')
    (tmp_path / "n.net.xml").write_text(NET)
    patch = compare_links(tmp_path / "n.net.xml", direct_junctions(etree.fromstring(xodr)))
    assert patch.unusable == ("junction 5 laneLink road 1 lane 1 -> road 2 lane -1",)
    assert patch.missing == () and patch.extra == (("2_0", "-3_0"),)
