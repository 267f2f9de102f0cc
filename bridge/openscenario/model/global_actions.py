"""Storyboard actions on the world rather than on one entity (OpenSCENARIO GlobalAction):
variables and (deprecated) parameters, the environment. SI units: m, s, lux, radians."""

from __future__ import annotations

from dataclasses import dataclass

from hiyari.bridge.openscenario.model.positions import Position

__all__ = [
    "AddEntityAction",
    "DeleteEntityAction",
    "Environment",
    "EnvironmentAction",
    "Fog",
    "GlobalActionBody",
    "ParameterModifyAction",
    "ParameterSetAction",
    "SetMonitorAction",
    "TrafficAreaAction",
    "TrafficMix",
    "TrafficSignalControllerAction",
    "TrafficSinkAction",
    "TrafficSourceAction",
    "TrafficStopAction",
    "TrafficSwarmAction",
    "TrafficSignalStateAction",
    "Precipitation",
    "RoadCondition",
    "Sun",
    "VariableModifyAction",
    "VariableSetAction",
    "Weather",
    "Wind",
]


@dataclass(frozen=True)
class VariableSetAction:
    """Set variable ``variable`` to ``value`` (text, converted to the variable's type)."""

    variable: str
    value: str


@dataclass(frozen=True)
class VariableModifyAction:
    """Change numeric variable ``variable``: ``op`` "add" adds ``value``, "multiply" multiplies
    by it."""

    variable: str
    op: str
    value: float


@dataclass(frozen=True)
class ParameterSetAction:
    """Deprecated since 1.2 (VariableSetAction replaces it): set parameter ``parameter`` to
    ``value`` at run time. Attributes that referenced the parameter were resolved when the
    file was read; ParameterConditions see the new value."""

    parameter: str
    value: str


@dataclass(frozen=True)
class ParameterModifyAction:
    """Deprecated since 1.2: ``op`` "add" / "multiply" a numeric parameter by ``value``."""

    parameter: str
    op: str
    value: float


@dataclass(frozen=True)
class Sun:
    """Sun position and light as OpenSCENARIO gives them: ``azimuth`` (rad from north,
    clockwise: pi / 2 is east), ``elevation`` (rad above the horizon), ``illuminance`` (lux;
    None: not given)."""

    azimuth: float
    elevation: float
    illuminance: float | None = None


@dataclass(frozen=True)
class Fog:
    """Fog with a visual range, m."""

    visual_range: float


@dataclass(frozen=True)
class Precipitation:
    """``kind``: dry, rain or snow; ``intensity`` mm/h (None: not given)."""

    kind: str
    intensity: float | None = None


@dataclass(frozen=True)
class Wind:
    """Wind from ``direction`` (rad) at ``speed`` m/s."""

    direction: float
    speed: float


@dataclass(frozen=True)
class Weather:
    """Weather: each part None when the file does not give it. ``cloud_cover``: the file's
    fractionalCloudCover (zeroOktas ... nineOktas) or deprecated cloudState; ``temperature``
    K; ``pressure`` Pa."""

    sun: Sun | None = None
    fog: Fog | None = None
    precipitation: Precipitation | None = None
    wind: Wind | None = None
    cloud_cover: str = ""
    temperature: float | None = None
    pressure: float | None = None


@dataclass(frozen=True)
class RoadCondition:
    """Road friction relative to the nominal (``friction_scale``, 1 = dry asphalt) and the
    file's wetness word ('' when not given)."""

    friction_scale: float
    wetness: str = ""


@dataclass(frozen=True)
class Environment:
    """Time of day (ISO date-time text, ``animated``: the clock runs with the simulation),
    weather and road condition; a part is None when the file does not give it."""

    name: str
    time_of_day: str | None = None
    animated: bool = False
    weather: Weather | None = None
    road: RoadCondition | None = None


@dataclass(frozen=True)
class EnvironmentAction:
    """Set the environment (the parts it gives replace the current ones)."""

    environment: Environment


@dataclass(frozen=True)
class AddEntityAction:
    """Put entity ``entity`` (declared in Entities, out of the simulation) at ``position``."""

    entity: str
    position: Position


@dataclass(frozen=True)
class DeleteEntityAction:
    """Take entity ``entity`` out of the simulation (its conditions see it absent)."""

    entity: str


@dataclass(frozen=True)
class SetMonitorAction:
    """Set monitor ``monitor`` (declared in MonitorDeclarations) to ``value``."""

    monitor: str
    value: bool


@dataclass(frozen=True)
class TrafficSignalStateAction:
    """Set traffic signal ``signal`` (a SUMO traffic light of the imported net) to ``state``:
    SUMO's letters per link (r y g G o O u), or OpenSCENARIO's lamp triple "red;yellow;green"
    of on / off words for every link."""

    signal: str
    state: str


@dataclass(frozen=True)
class TrafficSignalControllerAction:
    """Switch traffic-light controller ``controller`` (a SUMO traffic light) to its phase
    ``phase`` (a phase name, or its index)."""

    controller: str
    phase: str


@dataclass(frozen=True)
class TrafficMix:
    """What a traffic action inserts: (weight, vehicle category, length, width, height m;
    sizes None: SUMO's defaults for the category) entries."""

    entries: tuple[tuple[float, str, float | None, float | None, float | None], ...]


@dataclass(frozen=True)
class TrafficSourceAction:
    """SUMO traffic inserted ``rate`` vehicles per second within ``radius`` m of
    ``position`` (on its lane), at ``speed`` m/s (None: the lane's limit); ``name``: the
    traffic's name (TrafficStopAction ends it)."""

    name: str
    position: Position
    radius: float
    rate: float
    speed: float | None
    mix: TrafficMix


@dataclass(frozen=True)
class TrafficSinkAction:
    """SUMO traffic within ``radius`` m of ``position`` is taken out, ``rate`` vehicles per
    second at most (None: all)."""

    name: str
    position: Position
    radius: float
    rate: float | None


@dataclass(frozen=True)
class TrafficSwarmAction:
    """``count`` SUMO vehicles kept around entity ``central`` in the ellipse of semi-axes
    ``semi_major`` (along its heading) and ``semi_minor`` m whose centre is ``offset`` m ahead
    of it, outside ``inner_radius`` m; inserted at a speed in ``speed_range`` (m/s; None:
    the lane's limit), driving its way with weight ``same`` against ``opposite``."""

    name: str
    central: str
    inner_radius: float
    semi_major: float
    semi_minor: float
    offset: float
    count: int
    speed_range: tuple[float, float] | None
    same: float
    opposite: float
    mix: TrafficMix


@dataclass(frozen=True)
class TrafficAreaAction:
    """``count`` SUMO vehicles put in an area: inside the ``polygon`` (world x, y points),
    or on the ``ranges`` of roads ((road, s from, s to, lane ids or () for every lane));
    ``continuous``: kept at that number while it runs (vehicles leaving no longer count)."""

    name: str
    count: int
    continuous: bool
    polygon: tuple[Position, ...]
    ranges: tuple[tuple[str, float, float, tuple[int, ...]], ...]
    mix: TrafficMix


@dataclass(frozen=True)
class TrafficStopAction:
    """End the traffic action called ``name`` (its vehicles drive on)."""

    name: str


GlobalActionBody = (
    VariableSetAction
    | VariableModifyAction
    | ParameterSetAction
    | ParameterModifyAction
    | EnvironmentAction
    | AddEntityAction
    | DeleteEntityAction
    | SetMonitorAction
    | TrafficSignalStateAction
    | TrafficSignalControllerAction
    | TrafficSourceAction
    | TrafficSinkAction
    | TrafficSwarmAction
    | TrafficAreaAction
    | TrafficStopAction
)
