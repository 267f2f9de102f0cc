"""Read an OpenSCENARIO XML scenario (1.0 - 1.3) into the scenario model.

``read_scenario(path, parameters)`` validates the file against the 1.3 schema, resolves its
parameters (``parameters`` overrides the file's top-level ParameterDeclarations, as a sweep
does), expands CatalogReferences from the file's CatalogLocations, resolves the RoadNetwork's
LogicFile relative to the file, and maps every element onto the model. An element the engine
cannot execute is a HiyariError naming the element, the file and the line.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

from lxml import etree

from hiyari.bridge.openscenario.model.actions import Action
from hiyari.bridge.openscenario.model.conditions import EntityCondition, Trigger
from hiyari.bridge.openscenario.model.entities import ControllerSpec, Entity, EntityKind
from hiyari.bridge.openscenario.model.storyboard import (
    Act,
    Event,
    InitAction,
    Maneuver,
    ManeuverGroup,
    Scenario,
    SignalController,
    SignalPhase,
    Story,
    Storyboard,
)
from hiyari.bridge.openscenario.xosc import document
from hiyari.bridge.openscenario.xosc.catalogs import Catalogs
from hiyari.bridge.openscenario.xosc.context import Ctx, Scope
from hiyari.bridge.openscenario.xosc.elements.read_actions import (
    read_controller,
    read_private_action,
)
from hiyari.bridge.openscenario.xosc.elements.read_conditions import read_trigger
from hiyari.bridge.openscenario.xosc.elements.read_global import (
    read_global_action,
    read_monitors,
    read_variables,
)
from hiyari.errors import HiyariError
from hiyari.traffic.actor_class import ActorClass

_VEHICLE_CLASS = {
    "car": ActorClass.CAR,
    "van": ActorClass.CAR,
    "truck": ActorClass.TRUCK,
    "trailer": ActorClass.TRUCK,
    "semitrailer": ActorClass.TRUCK,
    "bus": ActorClass.BUS,
    "tram": ActorClass.BUS,
    "train": ActorClass.BUS,
    "motorbike": ActorClass.MOTORCYCLE,
    "bicycle": ActorClass.BICYCLE,
}
#: Entity names taken as the ego when the caller does not name one (case-insensitive).
EGO_NAMES = ("ego", "hero")
_IGNORED_ROOT = (
    "FileHeader",
    "ParameterDeclarations",
    "VariableDeclarations",
    "MonitorDeclarations",
    "CatalogLocations",
    "RoadNetwork",
)


def read_scenario(
    path: str | Path, parameters: Mapping[str, object] | None = None, ego: str | None = None
) -> Scenario:
    """The scenario in ``path`` with ``parameters`` overriding its declared values.

    ``ego`` names the entity driven by the ego stack; by default the entity with the property
    ``type = ego_vehicle``, else one named Ego / hero (any case), else none.
    """
    path = Path(path).resolve()
    root = document.load(path)
    if root.find("Storyboard") is None:
        kind = next((k.tag for k in root if k.tag not in ("FileHeader",)), "nothing")
        raise HiyariError(
            f"{path}: not a scenario (it holds <{kind}>; read distributions with read_distribution)"
        )
    for el in root:
        if el.tag not in (*_IGNORED_ROOT, "Entities", "Storyboard"):
            raise Ctx(path, Scope()).unsupported(el)
    overrides = {k: _text(v) for k, v in (parameters or {}).items()}
    ctx = Ctx(path, Scope()).enter(root, overrides)
    ctx.catalogs = Catalogs.from_locations(ctx, root.find("CatalogLocations"))
    variables = read_variables(ctx, root.find("VariableDeclarations"))
    road = _road_network(ctx, root.find("RoadNetwork"))
    objects = ctx.child(root, "Entities")
    entities = tuple(_entity(ctx, o) for o in objects if o.tag != "EntitySelection")
    names = [e.name for e in entities]
    selections = _selections(ctx, objects.findall("EntitySelection"), entities)
    storyboard = _storyboard(ctx, root.find("Storyboard"), {*names, *selections})
    storyboard = expand_selections(storyboard, selections)
    header = root.find("FileHeader")
    return Scenario(
        name=path.stem if header is None else (header.get("description") or path.stem),
        entities=entities,
        storyboard=storyboard,
        ego=_pick_ego(entities, ego, path),
        road_network=road,
        parameters=dict(ctx.scope.values),
        source=path,
        parameter_types=dict(ctx.scope.types),
        variables=variables,
        monitors=read_monitors(ctx, root.find("MonitorDeclarations")),
        signal_controllers=_signal_controllers(ctx, root.find("RoadNetwork/TrafficSignals")),
    )


def _text(v: object) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return repr(v) if isinstance(v, float) else str(v)


def _road_network(ctx: Ctx, el: etree._Element | None) -> Path | None:
    if el is None:
        return None
    for child in el:
        if child.tag not in ("LogicFile", "SceneGraphFile", "UsedArea", "TrafficSignals"):
            raise ctx.unsupported(child)
    logic = el.find("LogicFile")
    if logic is None:
        return None
    p = Path(ctx.text(logic, "filepath"))
    p = p if p.is_absolute() else (ctx.file.parent / p).resolve()
    if not p.is_file():
        raise HiyariError(f"{ctx.where(logic)}: road network file {p} not found")
    return p


def _signal_controllers(ctx: Ctx, el: etree._Element | None) -> tuple[SignalController, ...]:
    out = []
    for c in [] if el is None else el.findall("TrafficSignalController"):
        phases = []
        for ph in c.findall("Phase"):
            group = ph.find("TrafficSignalGroupState")
            phases.append(
                SignalPhase(
                    ctx.text(ph, "name"),
                    ctx.num(ph, "duration"),
                    tuple(
                        (ctx.text(s, "trafficSignalId"), ctx.text(s, "state"))
                        for s in ph.findall("TrafficSignalState")
                    ),
                    "" if group is None else ctx.text(group, "state"),
                )
            )
        if sum(p.duration for p in phases) <= 0:
            raise HiyariError(f"{ctx.where(c)}: signal controller phases of no duration")
        out.append(
            SignalController(
                ctx.text(c, "name"),
                tuple(phases),
                ctx.num(c, "delay", 0.0),
                ctx.text(c, "reference", ""),
            )  # fmt: skip
        )
    return tuple(out)


def _pick_ego(entities: tuple[Entity, ...], ego: str | None, path: Path) -> str | None:
    names = [e.name for e in entities]
    if ego is not None:
        if ego not in names:
            raise HiyariError(f"{path}: --ego {ego}: no such entity (entities: {', '.join(names)})")
        return ego
    for e in entities:
        if e.properties.get("type") == "ego_vehicle":
            return e.name
    return next((n for n in names if n.lower() in EGO_NAMES), None)


def no_ego(sc: Scenario) -> str:
    """The one-line error for a scenario without an ego: its entities, and the option that
    names one."""
    names = ", ".join(e.name for e in sc.entities) or "none"
    return (
        f"{sc.source or sc.name}: the scenario has no ego: no entity has the property "
        f"type=ego_vehicle or is named {' / '.join(EGO_NAMES)} (entities: {names}); name the "
        "ego with --ego NAME"
    )


# ---------------------------------------------------------------------------- entities
#: ByType object types and the entity kinds they select (external objects: none in hiyari).
_BY_TYPE = {
    "vehicle": (EntityKind.VEHICLE,),
    "pedestrian": (EntityKind.PEDESTRIAN,),
    "miscellaneous": (EntityKind.MISC,),
    "external": (),
}


def _selections(
    ctx: Ctx, els: list[etree._Element], entities: tuple[Entity, ...]
) -> dict[str, tuple[str, ...]]:
    """EntitySelections: name -> the entities they select (members by name, selections
    nested, or by type), in scenario order without repeats."""
    raw = {ctx.text(el, "name"): el for el in els}
    names = {e.name for e in entities}
    out: dict[str, tuple[str, ...]] = {}

    def expand(name: str, seen: tuple[str, ...]) -> tuple[str, ...]:
        if name in out:
            return out[name]
        if name in seen:
            raise HiyariError(f"{ctx.where(raw[name])}: entity selection {name!r} contains itself")
        members: list[str] = []
        for m in ctx.child(raw[name], "Members"):
            if m.tag == "ByType":
                kinds = _BY_TYPE[ctx.text(m, "objectType")]
                members += [e.name for e in entities if e.kind in kinds]
                continue
            ref = ctx.text(m, "entityRef")
            if ref in raw:
                members += expand(ref, (*seen, name))
            elif ref in names:
                members.append(ref)
            else:
                raise HiyariError(f"{ctx.where(m)}: no entity {ref!r} in the scenario")
        out[name] = tuple(dict.fromkeys(members))
        return out[name]

    for name in raw:
        expand(name, ())
    return out


def expand_selections(sb: Storyboard, selections: dict[str, tuple[str, ...]]) -> Storyboard:
    """``sb`` with every EntitySelection named as actors or triggering entities replaced by
    the entities it selects."""
    if not selections:
        return sb

    def names(refs: tuple[str, ...]) -> tuple[str, ...]:
        out: list[str] = []
        for r in refs:
            out += selections.get(r, (r,))
        return tuple(dict.fromkeys(out))

    def trig(t: Trigger) -> Trigger:
        return tuple(
            tuple(
                replace(c, body=replace(c.body, triggering=names(c.body.triggering)))
                if isinstance(c.body, EntityCondition)
                else c
                for c in group
            )
            for group in t
        )

    stories = tuple(
        replace(
            st,
            acts=tuple(
                replace(
                    act,
                    start_trigger=trig(act.start_trigger),
                    stop_trigger=trig(act.stop_trigger),
                    groups=tuple(
                        replace(
                            g,
                            actors=names(g.actors),
                            maneuvers=tuple(
                                replace(
                                    m,
                                    events=tuple(
                                        replace(e, start_trigger=trig(e.start_trigger))
                                        for e in m.events
                                    ),
                                )
                                for m in g.maneuvers
                            ),
                        )
                        for g in act.groups
                    ),
                )
                for act in st.acts
            ),
        )
        for st in sb.stories
    )
    init = tuple(replace(ia, entity=n) for ia in sb.init for n in names((ia.entity,)) or ("",))
    return replace(sb, init=init, stories=stories, stop_trigger=trig(sb.stop_trigger))


def _entity(ctx: Ctx, obj: etree._Element) -> Entity:
    if obj.tag != "ScenarioObject":
        raise ctx.unsupported(obj)
    name = ctx.text(obj, "name")
    controllers: dict[str, ControllerSpec] = {}
    for oc in obj.findall("ObjectController"):
        spec = read_controller(ctx, ctx.one(oc))
        key = ctx.opt(oc, "name") or spec.name
        if key in controllers:
            raise HiyariError(f"{ctx.where(oc)}: entity {name!r} has two controllers {key!r}")
        controllers[key] = spec
    controller = next(iter(controllers.values()), None)
    body = next(k for k in obj if k.tag != "ObjectController")
    if body.tag == "CatalogReference":
        body, bctx = ctx.catalogs.resolve(ctx, body)
    else:
        bctx = ctx
    bctx = bctx.enter(body)
    kind, category = _kind(bctx, body)
    box = bctx.child(body, "BoundingBox")
    dim, centre = bctx.child(box, "Dimensions"), bctx.child(box, "Center")
    perf = body.find("Performance")
    props = {}
    pr = body.find("Properties")
    for p in [] if pr is None else pr.findall("Property"):
        props[bctx.text(p, "name")] = bctx.text(p, "value")
    return Entity(
        name=name,
        kind=kind,
        actor_class=_VEHICLE_CLASS.get(category, ActorClass.CAR)
        if kind != EntityKind.PEDESTRIAN
        else ActorClass.PEDESTRIAN,
        length=bctx.num(dim, "length"),
        width=bctx.num(dim, "width"),
        height=bctx.num(dim, "height"),
        centre=(bctx.num(centre, "x"), bctx.num(centre, "y"), bctx.num(centre, "z")),
        category=category,
        max_speed=None if perf is None else bctx.num(perf, "maxSpeed"),
        max_accel=None if perf is None else bctx.num(perf, "maxAcceleration"),
        max_decel=None if perf is None else bctx.num(perf, "maxDeceleration"),
        controller=controller,
        properties=props,
        controllers=controllers,
    )


def _kind(ctx: Ctx, body: etree._Element) -> tuple[EntityKind, str]:
    if body.tag == "Vehicle":
        return EntityKind.VEHICLE, ctx.text(body, "vehicleCategory")
    if body.tag == "Pedestrian":
        cat = ctx.opt(body, "pedestrianCategory") or ctx.opt(body, "category") or "pedestrian"
        return EntityKind.PEDESTRIAN, cat
    if body.tag == "MiscObject":
        return EntityKind.MISC, ctx.text(body, "miscObjectCategory")
    raise ctx.unsupported(body)


# ---------------------------------------------------------------------------- storyboard
def _storyboard(ctx: Ctx, sb: etree._Element, entities: set[str]) -> Storyboard:
    init: list[InitAction] = []
    actions = ctx.child(ctx.child(sb, "Init"), "Actions")
    for el in actions:
        if el.tag == "GlobalAction":
            k = len(init)
            body = read_global_action(ctx, el)
            init.append(InitAction("", Action(f"Init:global:{k}", body, ctx.where(el))))
            continue
        if el.tag != "Private":
            raise ctx.unsupported(el)
        who = ctx.text(el, "entityRef")
        _known(ctx, el, who, entities)
        for k, pa in enumerate(el.findall("PrivateAction")):
            body = read_private_action(ctx, pa)
            init.append(InitAction(who, Action(f"Init:{who}:{k}", body, ctx.where(pa))))
    stories = tuple(_story(ctx, s, entities) for s in sb.findall("Story"))
    return Storyboard(tuple(init), stories, read_trigger(ctx, sb.find("StopTrigger")))


def _known(ctx: Ctx, el: etree._Element, name: str, entities: set[str]) -> None:
    if name not in entities:
        raise HiyariError(f"{ctx.where(el)}: no entity {name!r} in the scenario")


def _story(ctx: Ctx, el: etree._Element, entities: set[str]) -> Story:
    ctx = ctx.enter(el)
    acts = []
    for a in el.findall("Act"):
        groups = tuple(_group(ctx, g, entities) for g in a.findall("ManeuverGroup"))
        acts.append(
            Act(
                ctx.text(a, "name"),
                groups,
                read_trigger(ctx, a.find("StartTrigger")),
                read_trigger(ctx, a.find("StopTrigger")),
            )
        )
    return Story(ctx.text(el, "name"), tuple(acts))


def _group(ctx: Ctx, el: etree._Element, entities: set[str]) -> ManeuverGroup:
    actors_el = ctx.child(el, "Actors")
    actors = tuple(ctx.text(r, "entityRef") for r in actors_el.findall("EntityRef"))
    for r, name in zip(actors_el.findall("EntityRef"), actors, strict=True):
        _known(ctx, r, name, entities)
    maneuvers = []
    for m in el:
        if m.tag == "CatalogReference":
            mel, mctx = ctx.catalogs.resolve(ctx, m)
            maneuvers.append(_maneuver(mctx, mel))
        elif m.tag == "Maneuver":
            maneuvers.append(_maneuver(ctx, m))
    return ManeuverGroup(
        ctx.text(el, "name"),
        actors,
        tuple(maneuvers),
        ctx.flag(actors_el, "selectTriggeringEntities", False),
        ctx.int(el, "maximumExecutionCount", 1),
    )


def _maneuver(ctx: Ctx, el: etree._Element) -> Maneuver:
    if el.tag != "Maneuver":
        raise ctx.unsupported(el)
    ctx = ctx.enter(el)
    events = []
    for ev in el.findall("Event"):
        actions = []
        for a in ev.findall("Action"):
            kind = ctx.one(a)
            if kind.tag == "PrivateAction":
                body = read_private_action(ctx, kind)
            elif kind.tag == "GlobalAction":
                body = read_global_action(ctx, kind)
            else:
                raise ctx.unsupported(
                    kind, "a custom command means something only to the tool it was written for"
                )
            actions.append(Action(ctx.text(a, "name"), body, ctx.where(a)))
        priority = ctx.text(ev, "priority", "override")
        events.append(
            Event(
                ctx.text(ev, "name"),
                tuple(actions),
                read_trigger(ctx, ev.find("StartTrigger")),
                "override" if priority == "overwrite" else priority,
                ctx.int(ev, "maximumExecutionCount", 1),
            )
        )
    return Maneuver(ctx.text(el, "name"), tuple(events))


__all__ = ["ControllerSpec", "read_scenario"]
