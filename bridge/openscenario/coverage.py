"""Which elements of the ASAM OpenSCENARIO XML 1.3 schema hiyari executes, the element table
of docs/openscenario_elements.md made from the schema itself (tests/unit/openscenario/test_osc_element_table.py
fails when the table, the schema or the code disagree).

Every element the schema names is one of:

- executed: the reader maps it onto the scenario model and the engine runs it (the reader
  names it, or reads it as the one child of a choice it names: ``IMPLICIT``);
- read: read (or skipped) with no effect on a simulation (``READ``, with why);
- refused: the reader or the engine stops with a one-line error giving the reason
  (``REFUSED``: nothing in a SUMO-coupled closed loop can honour it);
- not yet: refused (``NOT_YET``), to be built.

    python -m hiyari.bridge.openscenario.coverage > docs/openscenario_elements.md
"""

from __future__ import annotations

import re
import sys
from functools import cache
from pathlib import Path

from lxml import etree

from hiyari.checkout import shared_dir

HERE = Path(__file__).resolve().parent
SCHEMA = HERE / "xosc" / "schema" / "OpenSCENARIO_1_3.xsd"
_XSD = "{http://www.w3.org/2001/XMLSchema}"

_ANIMATION = "hiyari's actors are rigid boxes with no animated parts"
_PEDALS = "hiyari's actors are kinematic: no pedals, gears or steering wheel to override"
_TRAILER = "SUMO moves no articulated trailers"
#: Elements refused with the reason (the one-line error gives it).
REFUSED = {
    "UserDefinedAction": "a custom command means something only to the tool it was written for",
    "CustomCommandAction": "a custom command means something only to the tool it was written for",
    "DomeImage": "hiyari renders no sky dome",
    "DomeFile": "hiyari renders no sky dome",
    "SensorReferenceSet": "hiyari's sensors see an entity all or none (no sensor by reference)",
    "SensorReference": "hiyari's sensors see an entity all or none (no sensor by reference)",
    "ExternalObjectReference": "nothing in hiyari resolves an object outside the scenario",
    "UserDefinedValueCondition": "a user-defined value comes from outside the scenario",
    "UserDefinedDistribution": "a user-defined distribution is expanded by the tool it was "
    "written for",
    **dict.fromkeys(
        (
            "AnimationAction",
            "AnimationType",
            "AnimationState",
            "AnimationFile",
            "ComponentAnimation",
            "PedestrianAnimation",
            "PedestrianGesture",
            "UserDefinedAnimation",
            "UserDefinedComponent",
            "VehicleComponent",
        ),
        _ANIMATION,
    ),  # fmt: skip
    **dict.fromkeys(
        (
            "OverrideControllerValueAction",
            "Throttle",
            "Brake",
            "Clutch",
            "ParkingBrake",
            "SteeringWheel",
            "Gear",
            "ManualGear",
            "AutomaticGear",
            "BrakeForce",
            "BrakePercent",
        ),
        _PEDALS,
    ),  # fmt: skip
    **dict.fromkeys(
        (
            "TrailerAction",
            "ConnectTrailerAction",
            "DisconnectTrailerAction",
            "Trailer",
            "TrailerCoupler",
            "TrailerHitch",
            "TrailerRef",
        ),
        _TRAILER,
    ),  # fmt: skip
}
#: Elements not executed yet (refused as "not supported by hiyari").
NOT_YET = {}
#: Elements read (or skipped) with no effect on the simulation, and why.
READ = {
    "License": "file metadata",
    "FileHeader": "file metadata (its revision is checked)",
    "Color": "a lamp's colour (SUMO's signals have none)",
    "ColorRgb": "a lamp's colour (SUMO's signals have none)",
    "ColorCmyk": "a lamp's colour (SUMO's signals have none)",
    "VehicleRoleDistribution": "traffic roles: SUMO's driver model drives the traffic",
    "VehicleRoleDistributionEntry": "traffic roles: SUMO's driver model drives the traffic",
    "ControllerDistribution": "traffic controllers: SUMO's driver model drives the traffic",
    "ControllerDistributionEntry": "traffic controllers: SUMO's driver model drives the traffic",
    "Axles": "the motion is kinematic (positions refer to the rear axle)",
    "FrontAxle": "the motion is kinematic",
    "RearAxle": "the motion is kinematic",
    "AdditionalAxle": "the motion is kinematic",
    "CustomContent": "content for other tools",
    "File": "files named in properties",
    "SceneGraphFile": "hiyari builds its 3D scene from the OpenDRIVE road",
    "UsedArea": "the whole road is imported",
    "OpenScenario": "the root element is read under its name OpenSCENARIO",
}
#: Elements executed though the reader does not name them: the one child of a choice it
#: reads, or entries of a list it walks.
IMPLICIT = {
    "AbsoluteSpeed", "AbsoluteTargetLane", "AbsoluteTargetLaneOffset", "AddEntityAction",
    "Environment", "FromLaneCoordinates", "LightStateAction", "ModifyAction", "None",
    "RelativeTargetSpeed", "TrafficSignalControllerAction", "VehicleLight", "VehicleCatalog",
    "ControllerCatalog", "PedestrianCatalog", "MiscObjectCatalog", "EnvironmentCatalog",
    "ManeuverCatalog", "TrajectoryCatalog", "RouteCatalog",
}  # fmt: skip


@cache
def schema_elements() -> tuple[str, ...]:
    """Every element name of the 1.3 schema, sorted."""
    tree = etree.parse(str(SCHEMA))
    return tuple(sorted({e.get("name") for e in tree.iter(f"{_XSD}element") if e.get("name")}))


@cache
def named_in_reader() -> frozenset[str]:
    """Element names the reader's code spells out."""
    text = "".join(p.read_text() for p in sorted((HERE / "xosc").rglob("*.py")))
    return frozenset(re.findall(r'"([A-Z][A-Za-z0-9]*)"', text))


def status(name: str) -> tuple[str, str]:
    """(status, why) of element ``name``: executed, read, refused, not yet, or unknown (the
    code neither reads nor refuses it)."""
    if name in REFUSED:
        return "refused", REFUSED[name]
    if name in NOT_YET:
        return "not yet", NOT_YET[name]
    if name in READ:
        return "read", READ[name]
    if name in named_in_reader() or name in IMPLICIT:
        return "executed", ""
    return "unknown", ""


@cache
def _test_texts() -> dict[str, str]:
    root = HERE.parents[1] / "tests"
    return {p.name: p.read_text() for p in sorted(root.rglob("test_*.py"))}


def test_of(name: str) -> str:
    """The test file exercising element ``name`` (the first that writes it; the Euro NCAP or
    ALKS files' tests for elements only those files use; '' when none)."""
    texts = _test_texts()
    own = sorted(texts, key=lambda n: (not n.startswith("test_osc_"), n))
    for n in own:
        if f"<{name}" in texts[n] or f"<{name}>" in texts[n]:
            return n
    data = shared_dir() / "data" / "openscenario"
    for files, test in (("ncap", "test_osc_ncap.py"), ("alks", "test_closed_loop_alks.py")):
        for f in sorted((data / files).rglob("*.xosc")):
            if f"<{name}" in f.read_text(errors="replace"):
                return test
    return ""


def table() -> str:
    """The element table (Markdown)."""
    rows = [(n, *status(n), test_of(n)) for n in schema_elements()]
    counts: dict[str, int] = {}
    for _, st, _, _ in rows:
        counts[st] = counts.get(st, 0) + 1
    summary = ", ".join(
        f"{counts[k]} {k}"
        for k in ("executed", "read", "refused", "not yet", "unknown")
        if k in counts
    )
    lines = [
        "# OpenSCENARIO XML 1.3 elements in hiyari",
        "",
        "Made from the schema by `python -m hiyari.bridge.openscenario.coverage` (do not edit: "
        "tests/unit/openscenario/test_osc_element_table.py checks it against the schema and the code).",
        "",
        f"{len(rows)} elements: {summary}. *executed*: read into the scenario model and run; "
        "*read*: read with no effect on a simulation; *refused*: a one-line error with the "
        "reason (what a SUMO-coupled closed loop cannot honour); *not yet*: refused, to be "
        "built.",
        "",
        "| element | status | why | test |",
        "| --- | --- | --- | --- |",
    ]
    lines += [f"| {n} | {st} | {why} | {test} |" for n, st, why, test in rows]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.stdout.write(table())
