"""The junction check on hand-written net XML (no SUMO): a link that waits at an internal
junction (a left turn across oncoming traffic, links inside a large joined OSM junction) is
listed in its junction by the lane after that internal junction, and is checked along its
whole path from its first lane."""

from __future__ import annotations

from pathlib import Path

from hiyari.net.sumo.junction_check import check_junctions

J = "J"


def _net(path: Path) -> Path:
    """Junction ``J``: link 0 runs straight along y = x from a_0 to b_0; link 1 leaves a_1 by
    its first lane (0, 2) -> (10, 8), which crosses link 0, waits at an internal junction and
    goes on along y = 8 (x 10..20, clear of y = x) to c_0. The junction lists link 1 by its
    second lane, as SUMO does; the request says the two links are no foes."""
    path.write_text(f"""<net>
  <edge id=":{J}_0" function="internal"><lane id=":{J}_0_0" index="0" shape="0,0 20,20"/></edge>
  <edge id=":{J}_1" function="internal"><lane id=":{J}_1_0" index="0" shape="0,2 10,8"/></edge>
  <edge id=":{J}_2" function="internal"><lane id=":{J}_2_0" index="0" shape="10,8 20,8"/></edge>
  <junction id="{J}" type="priority" intLanes=":{J}_0_0 :{J}_2_0">
    <request index="0" response="00" foes="00" cont="0"/>
    <request index="1" response="00" foes="00" cont="1"/>
  </junction>
  <connection from="a" to="b" fromLane="0" toLane="0" via=":{J}_0_0"/>
  <connection from="a" to="c" fromLane="1" toLane="0" via=":{J}_1_0"/>
  <connection from=":{J}_0" to="b" fromLane="0" toLane="0"/>
  <connection from=":{J}_1" to="c" fromLane="0" toLane="0" via=":{J}_2_0"/>
  <connection from=":{J}_2" to="c" fromLane="0" toLane="0"/>
</net>""")  # fmt: skip
    return path


def test_a_link_after_an_internal_junction_is_checked_along_its_whole_path(tmp_path):
    report = check_junctions(_net(tmp_path / "n.net.xml"))
    assert report.unregulated == [(J, f":{J}_0_0", f":{J}_2_0")]
    assert not report.phantom
