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
