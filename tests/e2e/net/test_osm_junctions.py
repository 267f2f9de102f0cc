"""Where netconvert's junctions let SUMO's vehicles run into each other, on small OSM files
written for each case (see hiyari.net.sumo.osm.junction_repair): a staggered junction that
netconvert would join is converted node by node, a crossing drawn along cars that are not
its foes is narrowed clear of them, and a car lane that nothing leads into, 0.2 m long, is
closed to vehicles."""

from __future__ import annotations

from lxml import etree
from osm_authoring import crossing_at_junction, dead_start, staggered_junction

from hiyari.net.sumo.osm import import_osm
from hiyari.net.sumo.osm.junction_repair import (
    MIN_CROSSING_WIDTH,
    car_conflicts,
    crossings_along_cars,
)


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


def test_a_crossing_along_cars_that_are_not_its_foes_is_narrowed_clear_of_them(tmp_path):
    doc = crossing_at_junction()
    warnings: list[str] = []
    osm = doc.write(tmp_path / "c.osm")
    net = import_osm(osm, tmp_path / "c.net.xml", warn=warnings.append)
    j = str(doc.ids["J"])
    narrowed = [w for w in warnings if "narrowed" in w]
    # the two crossings over Main Street's legs, 4 m wide, reached into the side street's
    # straight-on lanes; from their outer edges 2 m are left clear of those cars
    assert len(narrowed) == 2 and all(
        w.startswith(f"{osm}: junction {j}: crossing :{j}_c") and "narrowed from 4 m to 2.0 m" in w
        for w in narrowed
    )
    root = _root(net)
    widths = [float(ln.get("width")) for e in root.iter("edge") if e.get("function") == "crossing"
              and e.get("id").startswith(f":{j}_c") for ln in e.iter("lane")]  # fmt: skip
    assert sorted(widths) == [MIN_CROSSING_WIDTH, MIN_CROSSING_WIDTH]
    assert crossings_along_cars(root) == []  # every car link CLEARANCE or more away
