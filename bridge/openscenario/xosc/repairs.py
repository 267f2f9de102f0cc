"""Repair known deviations from the OpenSCENARIO 1.3 schema in a parsed file, before validation.

Third-party tools write scenario and catalog files that the 1.3 schema refuses but whose
meaning is not in doubt (esmini reads them all). The pre-pass rewrites the parsed tree (never
the user's file) to the reading the authors' tool gives, one warning line per repair:
``<file>:<line>: <element>: <what was done>``. Deviations whose intended reading is not
unambiguous are not repaired: the schema check then refuses them in one line.

``DEVIATIONS`` is the table: the deviation, its repair, who writes it (docs/guide/openscenario.md
lists the same table).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime

from lxml import etree

from hiyari.xml_repair import Repair
from hiyari.xml_repair import tag as _tag


def _note(out: list[Repair], el: etree._Element, element: str, action: str) -> None:
    out.append(Repair(el.sourceline or 0, element, action))


#: Elements declaring a parameter or variable by name, and the attributes naming one.
_DECLARATIONS = ("ParameterDeclaration", "VariableDeclaration")
_NAME_REFS = ("parameterRef", "variableRef")
#: Elements of the schema type TransitionDynamics.
_TRANSITIONS = ("SpeedActionDynamics", "LaneChangeActionDynamics")
#: Attributes of type xsd:boolean wherever the 1.3 schema uses them (``value`` is left out:
#: it is a string or a number on other elements).
_BOOLEANS = frozenset(
    "activateAnimation activateLateral activateLighting activateLongitudinal active alongRoute "
    "animation closed continuous freeSpace freespace graphics lateral lighting longitudinal loop "
    "oppositeLanes selectTriggeringEntities sensors traffic".split()
)


def _dollar_names(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    for el in root.iter(_DECLARATIONS):
        name = el.get("name", "")
        if name.startswith("$"):
            _note(out, el, _tag(el, "name"), f"declared as {name[1:]} (the leading $ removed)")
            el.set("name", name[1:])
    for el in root.iter(etree.Element):
        for attr in _NAME_REFS:
            ref = el.get(attr, "")
            if ref.startswith("$") and not ref.startswith("${"):
                _note(out, el, _tag(el, attr), f"names {ref[1:]} (the leading $ removed)")
                el.set(attr, ref[1:])
    return out


def _negative_rates(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    for el in root.iter(_TRANSITIONS):
        value = el.get("value", "")
        try:
            negative = float(value) < 0
        except ValueError:
            continue  # a parameter: evaluated (and checked) by the reader
        if negative:
            _note(out, el, _tag(el, "dynamicsDimension", "value"),
                  f"negative value read as {value.lstrip('-')}")  # fmt: skip
            el.set("value", value.lstrip("-"))
    return out


def _step_dynamics(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    for el in root.iter(_TRANSITIONS):
        if el.get("dynamicsShape") != "step":
            continue
        added = [(a, v) for a, v in (("value", "0"), ("dynamicsDimension", "time"))
                 if el.get(a) is None]  # fmt: skip
        if added:
            said = ", ".join(f'{a}="{v}"' for a, v in added)
            _note(out, el, _tag(el, "dynamicsShape"), f"{said} added (a step takes no time)")
        for a, v in added:
            el.set(a, v)
    return out


def _booleans(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    for el in root.iter(etree.Element):
        for attr, value in el.attrib.items():
            low = value.lower()
            if attr in _BOOLEANS and low in ("true", "false") and value != low:
                _note(out, el, _tag(el, attr), f'read as {attr}="{low}"')
                el.set(attr, low)
    for el in root.iter(_DECLARATIONS):  # a boolean parameter's value is an xsd:boolean too
        value = el.get("value", "")
        typed = "boolean" in (el.get("parameterType"), el.get("variableType"))
        if typed and value.lower() in ("true", "false") and value != value.lower():
            _note(out, el, _tag(el, "name", "value"), f'read as value="{value.lower()}"')
            el.set("value", value.lower())
    return out


def _bool_type(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    for el in root.iter(_DECLARATIONS):
        if el.get("parameterType") == "bool" or el.get("variableType") == "bool":
            attr = "parameterType" if el.get("parameterType") == "bool" else "variableType"
            _note(out, el, _tag(el, "name", attr), f'read as {attr}="boolean"')
            el.set(attr, "boolean")
    return out


def _condition_edge(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    for el in root.iter("Condition"):
        if el.get("conditionEdge") is not None:
            continue
        old = el.get("edge")
        if old is not None:  # the OpenSCENARIO 0.9 name of the attribute
            del el.attrib["edge"]
            el.set("conditionEdge", old)
            _note(out, el, _tag(el, "name"), f'edge="{old}" read as conditionEdge="{old}"')
        else:
            el.set("conditionEdge", "none")
            _note(out, el, _tag(el, "name"), 'no conditionEdge: conditionEdge="none"')
    return out


def _trailer_entity_ref(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    for vehicle in root.iter("Vehicle"):
        for trailer in vehicle.findall("Trailer"):
            ref = trailer.find("EntityRef")
            if ref is not None:
                vehicle.remove(trailer)
                _note(out, trailer, f'<Vehicle name="{vehicle.get("name")}"> <Trailer><EntityRef '
                      f'entityRef="{ref.get("entityRef")}"/>',
                      "pre-1.3 trailer reference dropped: the trailer is ignored")  # fmt: skip
    return out


def _header_text(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    header = root.find("FileHeader")
    for attr in ("author", "description"):
        if header is not None and header.get(attr) is None:
            header.set(attr, "")
            _note(out, header, "<FileHeader>", f'no {attr}: {attr}="" added')
    return out


_DATE_TIME = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?(Z|[+-]\d\d:\d\d)?")
#: What a FileHeader date that is no xsd:dateTime is read as (nothing reads the date).
NO_DATE = "1970-01-01T00:00:00"


def _is_date_time(text: str) -> bool:
    if not _DATE_TIME.fullmatch(text):
        return False
    try:
        datetime.fromisoformat(text[:19])
    except ValueError:
        return False
    return True


def _header_date(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    header = root.find("FileHeader")
    date = None if header is None else header.get("date")
    if header is not None and date is not None and not _is_date_time(date):
        _note(out, header, _tag(header, "date"), f"not a date and time: read as {NO_DATE} "
              "(the header's date is not used)")  # fmt: skip
        header.set("date", NO_DATE)
    return out


def _property_in_declarations(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    for decls in root.iter("ParameterDeclarations"):
        owner = decls.getparent()
        for prop in decls.findall("Property"):
            props = owner.find("Properties") if owner is not None else None
            if props is None:  # only elements with Properties are repaired
                continue
            _note(out, prop, f'<{owner.tag} name="{owner.get("name")}"> ' + _tag(prop, "name"),
                  "inside ParameterDeclarations: moved to the Properties")  # fmt: skip
            decls.remove(prop)
            props.insert(0, prop)
    return out


#: Storyboard elements whose ``name`` the schema requires (a StoryboardElementStateCondition
#: refers to them by it).
_NAMED = ("Story", "Act", "ManeuverGroup", "Maneuver", "Event", "Action")


def _unnamed(root: etree._Element) -> list[Repair]:
    out: list[Repair] = []
    for el in root.iter(_NAMED):
        if el.get("name") is None and el.getparent() is not None:
            name = f"unnamed {el.tag} at line {el.sourceline or 0}"
            _note(out, el, f"<{el.tag}>", f'no name: named "{name}" (nothing can refer to it)')
            el.set("name", name)
    return out


@dataclass(frozen=True)
class Deviation:
    """One known deviation: what the file says, how it is read, who writes it."""

    deviation: str
    repair: str
    writer: str
    apply: Callable[[etree._Element], list[Repair]]


#: The known deviations, applied in this order (docs/guide/openscenario.md: the same table).
DEVIATIONS = (
    Deviation("`name=\"$X\"` on a ParameterDeclaration / VariableDeclaration, "
              "`parameterRef=\"$X\"`, `variableRef=\"$X\"`",
              "the name without `$`", "esmini examples, scenariogeneration",
              _dollar_names),
    Deviation("negative TransitionDynamics `value` (a rate given with the sign of the change)",
              "its absolute value", "esmini examples", _negative_rates),
    Deviation("`dynamicsShape=\"step\"` without `value` / `dynamicsDimension`",
              "`value=\"0\"`, `dynamicsDimension=\"time\"`", "esmini examples", _step_dynamics),
    Deviation("`parameterType=\"bool\"`", "`boolean`", "esmini catalogs", _bool_type),
    Deviation("`True` / `False` (any case) for an xsd:boolean attribute or a boolean "
              "parameter's value", "`true` / `false`",
              "esmini examples", _booleans),
    Deviation("Condition without `conditionEdge` (or with the 0.9 name `edge`)",
              "`conditionEdge=\"none\"` (or the `edge` value)", "esmini examples",
              _condition_edge),
    Deviation("`<Trailer><EntityRef/></Trailer>` inside a Vehicle (pre-1.3)",
              "dropped: the trailer is ignored", "esmini catalogs", _trailer_entity_ref),
    Deviation("FileHeader without `author` / `description`", "the empty text",
              "esmini catalogs", _header_text),
    Deviation("FileHeader `date` that is no xsd:dateTime (`2020-10-204T10:00:00`)",
              f"`{NO_DATE}` (nothing reads the date)", "esmini catalogs", _header_date),
    Deviation("`<Property>` inside an element's ParameterDeclarations",
              "moved to the element's Properties", "esmini catalogs",
              _property_in_declarations),
    Deviation("Story / Act / ManeuverGroup / Maneuver / Event / Action without `name`",
              "`name=\"unnamed <element> at line <n>\"` (no condition can refer to it)",
              "esmini examples", _unnamed),
)  # fmt: skip


def repair(root: etree._Element) -> list[Repair]:
    """Apply every repair of ``DEVIATIONS`` to the tree under ``root`` (in place); the
    repairs made, in table order."""
    out: list[Repair] = []
    for d in DEVIATIONS:
        out += d.apply(root)
    return out
