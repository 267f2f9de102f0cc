"""A user's SUMO scenario written in tests, laid out as public city scenarios are (MoST,
LuST: the configuration in ``scenario/``, its inputs in ``in/``, named relative to it): the
OSM test town's net, its buildings as an additional polygon file, vehicle and pedestrian
flows in two route files, and a time window that does not start at 0."""

from __future__ import annotations

from pathlib import Path

from lxml import etree
from osm_authoring import town

from hiyari.net.sumo.osm import import_osm

BEGIN, END = 100.0, 700.0
#: (id, from edge, to edge, vehicles per hour): A-B-E-F, F-E-D-A, A-D-E-H on the town.
FLOWS = (("east", "11#0", "12#2", 360), ("west", "-12#2", "-14", 360), ("south", "14", "17", 240))
#: (id, from edge, to edge, persons per hour) walking the sidewalks.
WALKS = (("walk_e", "11#0", "12#2", 240), ("walk_s", "14", "17", 240))


def write_scenario(folder: Path) -> Path:
    """Write the scenario into ``folder``; return the .sumocfg."""
    inputs = folder / "in"
    (inputs / "route").mkdir(parents=True)
    (inputs / "add").mkdir()
    osm = town().write(folder / "town.osm")
    net = import_osm(osm, inputs / "town.net.xml")
    (inputs / "town.poly.xml").rename(inputs / "add" / "buildings.poly.xml")
    routes = etree.Element("routes")
    for fid, a, b, per_hour in FLOWS:
        etree.SubElement(routes, "flow", id=fid, begin=f"{BEGIN:g}", end=f"{END:g}",
                         vehsPerHour=str(per_hour), departLane="best", departSpeed="max",
                         **{"from": a, "to": b})  # fmt: skip
    etree.ElementTree(routes).write(str(inputs / "route" / "cars.rou.xml"), pretty_print=True)
    persons = etree.Element("routes")
    for fid, a, b, per_hour in WALKS:
        flow = etree.SubElement(persons, "personFlow", id=fid, begin=f"{BEGIN:g}",
                                end=f"{END:g}", personsPerHour=str(per_hour))  # fmt: skip
        etree.SubElement(flow, "walk", **{"from": a, "to": b})
    etree.ElementTree(persons).write(str(inputs / "route" / "walks.rou.xml"), pretty_print=True)
    (folder / "scenario").mkdir()
    cfg = folder / "scenario" / "town.sumocfg"
    cfg.write_text(
        f"""<?xml version="1.0" encoding="UTF-8"?>
<configuration>
    <input>
        <net-file value="../in/{net.name}"/>
        <route-files value="../in/route/cars.rou.xml,../in/route/walks.rou.xml"/>
        <additional-files value="../in/add/buildings.poly.xml"/>
    </input>
    <time>
        <begin value="{BEGIN:g}"/>
        <end value="{END:g}"/>
        <step-length value="0.5"/>
    </time>
    <processing>
        <time-to-teleport value="120"/>
    </processing>
</configuration>
"""
    )
    return cfg


#: The road scenario's window (s) and flows on the straight ALKS road's opposite carriageway
#: (id, lane, vehicles per hour); the second uses a vehicle type from the additional file.
ROAD_BEGIN, ROAD_END = 50.0, 200.0
ROAD_FLOWS = (("back", "1", 900), ("vans", "3", 600))


def write_road_scenario(folder: Path, net: Path) -> Path:
    """A SUMO scenario on ``net`` (hiyari's import of the straight ALKS road, edges "0" and
    "-0"): flows on the opposite carriageway "-0", one of them of a vehicle type defined in
    an additional file, over [ROAD_BEGIN, ROAD_END] s. Return the .sumocfg."""
    folder.mkdir(parents=True, exist_ok=True)
    add = etree.Element("additional")
    etree.SubElement(add, "vType", id="van", vClass="delivery", length="6.5", maxSpeed="25")
    etree.ElementTree(add).write(str(folder / "types.add.xml"), pretty_print=True)
    routes = etree.Element("routes")
    for fid, lane, per_hour in ROAD_FLOWS:
        kind = {"type": "van"} if fid == "vans" else {}
        etree.SubElement(routes, "flow", id=fid, begin=f"{ROAD_BEGIN:g}", end=f"{ROAD_END:g}",
                         vehsPerHour=str(per_hour), departLane=lane, departSpeed="max",
                         **{"from": "-0", "to": "-0"}, **kind)  # fmt: skip
    etree.ElementTree(routes).write(str(folder / "road.rou.xml"), pretty_print=True)
    cfg = folder / "road.sumocfg"
    cfg.write_text(
        f"""<?xml version="1.0" encoding="UTF-8"?>
<configuration>
    <input>
        <net-file value="{net}"/>
        <route-files value="road.rou.xml"/>
        <additional-files value="types.add.xml"/>
    </input>
    <time>
        <begin value="{ROAD_BEGIN:g}"/>
        <end value="{ROAD_END:g}"/>
    </time>
</configuration>
"""
    )
    return cfg
