"""Where netconvert's junctions let SUMO's vehicles run into each other, on small OSM files
written for each case (see hiyari.net.sumo.junction_repair): a staggered junction that
netconvert would join is converted node by node, and a car lane that nothing leads into,
0.2 m long, is closed to vehicles."""

from __future__ import annotations

from lxml import etree
from osm_authoring import dead_start, staggered_junction

from hiyari.net.sumo.junction_repair import car_conflicts
from hiyari.net.sumo.osm import import_osm


def _root(net) -> etree._Element:
    return etree.parse(str(net)).getroot()


def test_a_staggered_junction_is_not_joined_where_its_through_lanes_would_touch(tmp_path):
    doc = staggered_junction()
    warnings: list[str] = []
    net = import_osm(doc.write(tmp_path / "s.osm"), tmp_path / "s.net.xml", warn=warnings.append)
    a, b = doc.ids["A"], doc.ids["B"]
    # joined, the opposite through lanes of Main Street run 0.5 m apart across the jog
    assert [w for w in warnings if "converted unjoined" in w] == [
        f"{tmp_path / 's.osm'}: junction cluster_{a}_{b}: OSM nodes {a} {b} converted unjoined: "
        "joined, their car links cross without being foes or pass closer than 1.5 m"
    ]
    root = _root(net)
    junctions = {j.get("id") for j in root.iter("junction")}
    assert {str(a), str(b)} <= junctions and f"cluster_{a}_{b}" not in junctions
    assert car_conflicts(root) == []


def test_a_car_lane_nothing_leads_into_is_closed(tmp_path):
    doc = dead_start()
    warnings: list[str] = []
    net = import_osm(doc.write(tmp_path / "d.osm"), tmp_path / "d.net.xml", warn=warnings.append)
    root = _root(net)
    piece = next(e for e in root.iter("edge")
                 if e.get("from") == str(doc.ids["B"]) and e.get("to") == str(doc.ids["X"]))  # fmt: skip
    car = piece.find("lane[@index='1']")
    assert float(car.get("length")) < 1.0
    assert car.get("disallow") == "all"  # no vehicle can be inserted on it
    assert [w for w in warnings if "closed to vehicles" in w] == [
        f"{tmp_path / 'd.osm'}: lane {car.get('id')}: no lane leads into it and it is "
        f"{float(car.get('length')):.1f} m long: closed to vehicles (one inserted there would "
        "stand in the junction behind it)"
    ]
    assert piece.find("lane[@index='0']").get("allow") == "pedestrian"  # its sidewalk stays
