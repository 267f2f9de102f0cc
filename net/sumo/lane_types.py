"""The one table of OpenDRIVE lane types: who may use each lane and what its surface is.

Every OpenDRIVE lane type (ASAM OpenDRIVE 1.4 - 1.8, ``<lane type="...">``) maps to
- SUMO permissions (the vehicle classes allowed on the lane), written into the netconvert
  type map that the import uses, so the converted net carries them;
- a use (what the lane is for: traffic, shoulder, sidewalk, bike path, parking, verge), the
  role the permissions express (the road model's lane kinds follow from the permissions);
- a surface (asphalt, concrete, grass), which the 3D scene draws;
- whether the import keeps the lane by default (verge types only with ``all_lanes``).

Shoulders (``stop``, ``shoulder``, ``roadWorks``) and parking lanes are in the net and the
scene but closed to ordinary traffic: only emergency / authority vehicles (or, for parking,
SUMO's spare class ``custom1``) may use them, so generated traffic never drives there, while
scenario actors placed with ``Simulation.move_vehicle`` (free placement) may stand there.
Types unknown to the table are imported as verge (no traffic) only with ``all_lanes``.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, replace
from enum import StrEnum
from pathlib import Path

from lxml import etree

from hiyari.atomic import atomic_path


class LaneUse(StrEnum):
    """What a lane is for."""

    TRAFFIC = "traffic"  # ordinary road vehicles drive on it
    SHOULDER = "shoulder"  # paved, closed to ordinary traffic (emergency / authority only)
    PARKING = "parking"  # parked vehicles, no through traffic
    SIDEWALK = "sidewalk"  # pedestrians only
    BIKE = "bike"  # bicycles only
    RAIL = "rail"  # trams and trains
    VERGE = "verge"  # no traffic: borders, kerbs, medians, restricted areas


class Surface(StrEnum):
    """The scene material of a lane's surface (names of ``hiyari.net.mesh.materials``)."""

    ASPHALT = "asphalt"
    CONCRETE = "concrete"
    GRASS = "grass"


#: Road vehicles of SUMO (every class that drives on roads, bicycles included).
ROAD_VEHICLES = (
    "private passenger taxi bus coach delivery truck trailer motorcycle moped evehicle hov "
    "emergency authority army vip custom1 custom2 bicycle"
).split()
#: Motorway-style lanes: no bicycles or mopeds.
MOTOR_VEHICLES = [c for c in ROAD_VEHICLES if c not in ("bicycle", "moped")]
#: Who may use a shoulder: vehicles on duty, never ordinary traffic.
ON_DUTY = ["emergency", "authority"]


@dataclass(frozen=True)
class LaneType:
    """One OpenDRIVE lane type. ``allow`` lists SUMO vehicle classes (empty: none);
    ``speed`` is the limit where the file gives none, m/s; ``priority`` is netconvert's
    road priority for right of way."""

    name: str
    use: LaneUse
    allow: tuple[str, ...]
    surface: Surface
    imported: bool
    speed: float = 13.89
    priority: int = 1


def _t(name: str, use: LaneUse, allow: list[str], surface: Surface, imported: bool = True,
       speed: float = 13.89, priority: int = 1) -> LaneType:  # fmt: skip
    return LaneType(name, use, tuple(allow), surface, imported, speed, priority)


_A, _C, _G = Surface.ASPHALT, Surface.CONCRETE, Surface.GRASS
_RAMP = 22.22  # netconvert's default speed on entries, exits and ramps, m/s

#: OpenDRIVE lane type -> use, permissions, surface, default import. Speeds and priorities are
#: netconvert's own defaults (SUMO data/typemap/opendriveNetconvert.typ.xml).
LANE_TYPES: dict[str, LaneType] = {
    t.name: t
    for t in (
        _t("driving", LaneUse.TRAFFIC, ROAD_VEHICLES, _A),
        _t("entry", LaneUse.TRAFFIC, ROAD_VEHICLES, _A, speed=_RAMP),
        _t("exit", LaneUse.TRAFFIC, ROAD_VEHICLES, _A, speed=_RAMP),
        _t("onRamp", LaneUse.TRAFFIC, MOTOR_VEHICLES, _A, speed=_RAMP),
        _t("offRamp", LaneUse.TRAFFIC, MOTOR_VEHICLES, _A, speed=_RAMP),
        _t("connectingRamp", LaneUse.TRAFFIC, MOTOR_VEHICLES, _A, speed=_RAMP),
        _t("mwyEntry", LaneUse.TRAFFIC, MOTOR_VEHICLES, _A, speed=_RAMP),  # OpenDRIVE 1.2
        _t("mwyExit", LaneUse.TRAFFIC, MOTOR_VEHICLES, _A, speed=_RAMP),  # OpenDRIVE 1.2
        _t("bidirectional", LaneUse.TRAFFIC, ROAD_VEHICLES, _A),
        _t("slipLane", LaneUse.TRAFFIC, ROAD_VEHICLES, _A),  # OpenDRIVE 1.7
        _t("bus", LaneUse.TRAFFIC, ["bus", "coach", *ON_DUTY], _A),  # OpenDRIVE 1.8
        _t("taxi", LaneUse.TRAFFIC, ["taxi", "bus", *ON_DUTY], _A),  # OpenDRIVE 1.8
        _t("HOV", LaneUse.TRAFFIC, ["hov", "bus", "coach", "taxi", *ON_DUTY], _A),  # 1.8
        _t("stop", LaneUse.SHOULDER, ON_DUTY, _A),
        _t("shoulder", LaneUse.SHOULDER, ON_DUTY, _A),
        _t("roadWorks", LaneUse.SHOULDER, ["authority"], _A, speed=1.39, priority=0),
        _t("parking", LaneUse.PARKING, ["custom1"], _A, speed=1.39),
        _t("sidewalk", LaneUse.SIDEWALK, ["pedestrian"], _C, speed=2.78, priority=-2),
        _t("walking", LaneUse.SIDEWALK, ["pedestrian"], _C, speed=2.78, priority=-2),  # 1.7
        _t("biking", LaneUse.BIKE, ["bicycle"], _A, speed=5.56, priority=-1),
        _t("tram", LaneUse.RAIL, ["tram"], _A, priority=2),
        _t(
            "rail",
            LaneUse.RAIL,
            ["rail", "rail_urban", "rail_electric", "rail_fast"],
            _A,
            speed=33.33,
            priority=3,
        ),  # fmt: skip
        _t("border", LaneUse.VERGE, [], _G, imported=False, priority=0),
        _t("curb", LaneUse.VERGE, [], _C, imported=False, priority=0),
        _t("median", LaneUse.VERGE, [], _G, imported=False, priority=0),
        _t("none", LaneUse.VERGE, [], _G, imported=False, priority=0),
        _t("restricted", LaneUse.VERGE, [], _A, imported=False, priority=0),
        _t("special1", LaneUse.VERGE, [], _A, imported=False, priority=0),
        _t("special2", LaneUse.VERGE, [], _A, imported=False, priority=0),
        _t("special3", LaneUse.VERGE, [], _A, imported=False, priority=0),
    )
}

#: Lanes of a type the table does not know are drawn as this (and carry no traffic).
UNKNOWN = LaneType("unknown", LaneUse.VERGE, (), Surface.GRASS, imported=False, priority=0)


def lane_type(name: str) -> LaneType:
    """The table's entry for an OpenDRIVE lane type (``UNKNOWN`` when it has none)."""
    return LANE_TYPES.get(name, UNKNOWN)


def write_type_map(path: str | Path, others: Iterable[str] = ()) -> Path:
    """Write the table as a netconvert type file (``--type-files``) and return its path.

    ``others`` are lane type names the table does not know (found in a file): they are
    written as ``UNKNOWN`` (netconvert would otherwise open them to every vehicle). Types not
    imported by default are marked ``discard``; netconvert's ``--opendrive.import-all-lanes``
    imports them anyway, closed to every vehicle.
    """
    root = etree.Element("types")
    unknown = [replace(UNKNOWN, name=n) for n in sorted(set(others) - LANE_TYPES.keys())]
    for t in [*LANE_TYPES.values(), *unknown]:
        attrs = {"id": t.name, "priority": str(t.priority), "speed": f"{t.speed:.2f}"}
        if t.allow:
            attrs["allow"] = " ".join(t.allow)
        else:
            attrs["disallow"] = "all"
        if not t.imported:
            attrs["discard"] = "true"
        etree.SubElement(root, "type", attrs)
    with atomic_path(path) as tmp:
        etree.ElementTree(root).write(str(tmp), pretty_print=True, encoding="UTF-8")
    return Path(path)
