"""Typed commands into a running SUMO simulation, and typed reads of what WorldState lacks.

Everything outside ``hiyari.traffic`` changes SUMO only through these methods (Simulation
inherits them): nobody else imports libsumo. Frames and units as in WorldState: network
metres, actor positions at the centre of the ground rectangle (SUMO's front-bumper position is
converted here, once), headings in radians counter-clockwise from +x (SUMO's compass angle is
converted here), speeds m/s, accelerations m/s^2, times s.
"""

from __future__ import annotations

import contextlib
import math
from collections import deque
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from itertools import compress, repeat
from typing import Any

import numpy as np

from hiyari.errors import HiyariError
from hiyari.kinematics import point_ahead

#: SUMO speed mode bits: 0 = no checks at all (scripted actors follow the script exactly);
#: 31 = every safety check on (SUMO's default).
SPEED_MODE_SCRIPTED = 0
SPEED_MODE_DEFAULT = 31
#: Lane-change mode 0: SUMO changes lanes only when told to.
LANE_CHANGE_SCRIPTED = 0


def heading_to_sumo_angle(heading: float) -> float:
    """Radians CCW from +x -> SUMO's compass degrees (clockwise from north)."""
    return (90.0 - math.degrees(heading)) % 360.0


@dataclass(frozen=True)
class VehicleType:
    """A SUMO vehicle type made at run time from a base type. Metres, m/s, m/s^2.

    ``vclass`` None keeps the base type's class (SUMO's ``passenger`` for DEFAULT_VEHTYPE,
    ``pedestrian`` for DEFAULT_PEDTYPE). ``shape`` sets SUMO's guiShape; a type of vClass
    ``ignoring`` (allowed on every lane: scripted actors such as a pedestrian on a motorway)
    is classified in the WorldState by its shape ("pedestrian", "bicycle", "truck", ...).
    """

    type_id: str
    length: float
    width: float
    height: float
    max_speed: float | None = None
    base: str = "DEFAULT_VEHTYPE"
    vclass: str | None = None
    accel: float | None = None
    decel: float | None = None
    shape: str | None = None


@dataclass(frozen=True)
class SignalLink:
    """One controlled link of a traffic light: index into the light's state string."""

    tls: str
    index: int
    from_lane: str
    to_lane: str
    via_lane: str


@dataclass(frozen=True)
class SumoReading:
    """One actor exactly as SUMO's own getters report it (for checks of WorldState): front
    position (m), compass angle (deg clockwise from north), speed (m/s), acceleration (m/s^2,
    vehicles only: nan for persons), sizes (m), lane and edge ids."""

    front: tuple[float, float, float]
    angle: float
    speed: float
    accel: float
    length: float
    width: float
    height: float
    lane: str
    edge: str


@dataclass(frozen=True)
class NextSignal:
    """The next traffic light ahead of a vehicle: distance (m) and its state letter for it."""

    tls: str
    distance: float
    state: str


class Commands:
    """The typed command and query surface of a Simulation (mixed into it)."""

    def _api(self) -> Any:  # the libsumo module; provided by Simulation
        raise NotImplementedError

    def _commanded(self, actor_ids: Sequence[str], persons: bool = False) -> None:
        """Commands are about to move these actors or set their speeds (Simulation's read
        scope then reads them every step: no speed bound holds for them)."""

    def _placed(self) -> None:
        """A moveToXY was issued: SUMO holds it until the next step (see Simulation.close)."""

    # ------------------------------------------------------------------ actors
    def define_vehicle_type(self, vt: VehicleType) -> None:
        """Create vehicle type ``vt.type_id`` as a copy of ``vt.base`` with the given sizes."""
        t = self._api().vehicletype
        t.copy(vt.base, vt.type_id)
        t.setLength(vt.type_id, vt.length)
        t.setWidth(vt.type_id, vt.width)
        t.setHeight(vt.type_id, vt.height)
        if vt.max_speed is not None:
            t.setMaxSpeed(vt.type_id, vt.max_speed)
        if vt.vclass is not None:
            t.setVehicleClass(vt.type_id, vt.vclass)
        if vt.accel is not None:
            t.setAccel(vt.type_id, vt.accel)
        if vt.decel is not None:
            t.setDecel(vt.type_id, vt.decel)
        if vt.shape is not None:
            t.setShapeClass(vt.type_id, vt.shape)

    def add_vehicle(
        self,
        vehicle_id: str,
        route: Sequence[str],
        type_id: str,
        lane: int | str,
        pos: float,
        speed: float,
        scripted: bool,
    ) -> None:
        """Insert a vehicle now on ``route`` (edge ids), lane index ``lane`` (or a SUMO
        departLane word such as "best"), its front at
        ``pos`` m along the first edge; ``scripted`` turns SUMO's speed and lane-change
        logic off so that commands alone move it."""
        s = self._api()
        rid = f"route_{vehicle_id}"
        if rid in s.route.getIDList():  # the same id inserted again (removed in between)
            rid = f"{rid}#{len(s.route.getIDList())}"
        s.route.add(rid, list(route))
        with self._adding(vehicle_id, "vehicle"):
            s.vehicle.add(
                vehicle_id,
                rid,
                typeID=type_id,
                departLane=str(lane),
                departPos=f"{pos:.3f}",
                departSpeed=f"{speed:.3f}",
            )
        if scripted:
            s.vehicle.setSpeedMode(vehicle_id, SPEED_MODE_SCRIPTED)
            s.vehicle.setLaneChangeMode(vehicle_id, LANE_CHANGE_SCRIPTED)

    def add_person(self, person_id: str, edge: str, pos: float, type_id: str, wait: float) -> None:
        """Insert a person standing on ``edge`` at ``pos`` m for ``wait`` s (scripted people
        are then moved with ``move_person``)."""
        p = self._api().person
        with self._adding(person_id, "person"):
            p.add(person_id, edge, pos=pos, typeID=type_id)
        p.appendWaitingStage(person_id, wait)

    def add_walking_person(
        self, person_id: str, edges: Sequence[str], pos: float, type_id: str, speed: float = -1.0
    ) -> None:
        """Insert a person who walks along ``edges`` (SUMO's pedestrian model moves it)."""
        if speed >= 0:  # a set walking speed may exceed the person's own maximum
            self._commanded((person_id,), persons=True)
        p = self._api().person
        with self._adding(person_id, "person"):
            p.add(person_id, edges[0], pos=pos, typeID=type_id)
        p.appendWalkingStage(person_id, list(edges), arrivalPos=-1.0, speed=speed)

    @contextlib.contextmanager
    def _adding(self, actor_id: str, kind: str) -> Iterator[None]:
        """Around one insertion: SUMO refusing an id it already has (running, or loaded to
        depart later) becomes one line. A user's SUMO scenario may name one of its own
        vehicles or persons as a scenario names its entity."""
        try:
            yield
        except self._api().TraCIException as exc:
            if "already exists" not in str(exc):
                raise
            raise HiyariError(f"cannot insert {actor_id!r}: the simulation already has a {kind} "
                              "of that id (the SUMO scenario's own)") from None  # fmt: skip

    def remove_actor(self, actor_id: str, is_person: bool = False) -> None:
        """Take a vehicle (or person) out of the simulation now."""
        s = self._api()
        if is_person:
            s.person.remove(actor_id)
        else:
            s.vehicle.remove(actor_id)

    def set_speed_mode(self, vehicle_id: str, mode: int) -> None:
        """SUMO's speed-mode bit field for one vehicle (SPEED_MODE_SCRIPTED, _DEFAULT, ...)."""
        self._commanded((vehicle_id,))
        self._api().vehicle.setSpeedMode(vehicle_id, mode)

    def set_lane_change_mode(self, vehicle_id: str, mode: int) -> None:
        """SUMO's lane-change-mode bit field for one vehicle."""
        self._api().vehicle.setLaneChangeMode(vehicle_id, mode)

    # ------------------------------------------------------------------ motion
    def set_speed(self, vehicle_id: str, speed: float) -> None:
        """Hold ``speed`` m/s from the next step (within the vehicle's speed-mode checks)."""
        self._commanded((vehicle_id,))
        self._api().vehicle.setSpeed(vehicle_id, speed)

    def set_speeds(self, vehicle_ids: Sequence[str], speeds: Sequence[float]) -> None:
        """``set_speed`` for many vehicles."""
        self._commanded(vehicle_ids)
        # libsumo's SWIG function itself, driven by map: no Python frame per vehicle
        set_speed = self._api()._libsumo.vehicle_setSpeed
        if len(vehicle_ids) != len(speeds):
            raise ValueError("set_speeds: arguments of different lengths")
        deque(map(set_speed, vehicle_ids, map(float, speeds)), maxlen=0)

    def release_speed(self, vehicle_id: str) -> None:
        """Hand the vehicle's speed back to its own SUMO driver."""
        self._api().vehicle.setSpeed(vehicle_id, -1.0)

    def set_acceleration(self, vehicle_id: str, accel: float, duration: float) -> None:
        """Accelerate at ``accel`` m/s^2 for ``duration`` s."""
        self._commanded((vehicle_id,))
        self._api().vehicle.setAcceleration(vehicle_id, accel, duration)

    def set_signals(self, vehicle_id: str, bits: int) -> None:
        """SUMO's signal bit field of a vehicle (1 right and 2 left indicator, 4 hazard
        lights, 8 brake lights, 16 low beam, 32 fog lights, 64 high beam, 128 reversing,
        1024 blue light); -1 gives them back to SUMO."""
        self._api().vehicle.setSignals(vehicle_id, bits)

    def signals(self, vehicle_id: str) -> int:
        """SUMO's signal bit field of a vehicle now."""
        return int(self._api().vehicle.getSignals(vehicle_id))

    def change_lane(self, vehicle_id: str, lane_index: int, duration: float) -> None:
        """Ask SUMO to move to lane ``lane_index`` of the current edge within ``duration`` s."""
        self._api().vehicle.changeLane(vehicle_id, lane_index, duration)

    def move_vehicle(
        self,
        vehicle_id: str,
        x: float,
        y: float,
        heading: float,
        length: float,
        speed: float | None = None,
        edge: str = "",
        lane: int = -1,
    ) -> None:
        """Place a vehicle's rectangle centre at (``x``, ``y``) facing ``heading`` for the next
        step (SUMO maps it to the nearest lane of ``edge`` when given, else of any edge);
        ``speed`` m/s is what SUMO reports for it (None: implied by the move)."""
        self._commanded((vehicle_id,))
        self._placed()
        s = self._api()
        fx, fy = (float(v) for v in point_ahead((x, y), heading, 0.5 * length))
        # keepRoute 2 | 4: anywhere, mapped to the nearest lane whatever its permissions, so a
        # scripted car stands on a shoulder or parking lane closed to ordinary traffic
        s.vehicle.moveToXY(
            vehicle_id, edge, lane, fx, fy, angle=heading_to_sumo_angle(heading), keepRoute=6
        )
        if speed is not None:
            s.vehicle.setSpeed(vehicle_id, speed)

    def move_vehicle_fronts(
        self,
        vehicle_ids: Sequence[str],
        edges: Sequence[str],
        lanes: Sequence[int],
        front_x: Sequence[float],
        front_y: Sequence[float],
        angle: Sequence[float],
        speed: np.ndarray | Sequence[float],
    ) -> None:
        """``move_vehicle`` for many vehicles, in SUMO's own terms (the scenario engine computes
        them in one compiled pass): front-bumper points x, y (m, lists of floats), SUMO angles
        (degrees clockwise from north, as :func:`heading_to_sumo_angle`), speeds (N,) m/s (NaN:
        leave the speed set last, SUMO holds it), edge ('' = any) and lane index (-1) each."""
        n = len(vehicle_ids)
        if {len(edges), len(lanes), len(front_x), len(front_y), len(angle), len(speed)} != {n}:
            raise ValueError("move_vehicle_fronts: arguments of different lengths")
        self._commanded(vehicle_ids)
        self._placed()
        speeds = speed.tolist() if isinstance(speed, np.ndarray) else list(speed)
        keep = [v == v for v in speeds]  # NaN: leave the speed set last
        # libsumo's SWIG functions themselves (its Python wrappers add a frame per call),
        # positional (vehID, edgeID, lane, x, y, angle, keepRoute 6 as in move_vehicle) and
        # driven by map (no Python loop): every move, then the speeds to set (each vehicle's
        # move still precedes its speed; vehicles do not interact until the step). The speeds
        # are sorted out before: Python run between SUMO's calls runs in cold caches
        c = self._api()._libsumo
        deque(
            map(c.vehicle_moveToXY, vehicle_ids, edges, lanes, front_x, front_y, angle,
                repeat(6, n)),
            maxlen=0,
        )  # fmt: skip
        if all(keep):
            deque(map(c.vehicle_setSpeed, vehicle_ids, speeds), maxlen=0)
        else:
            ids = compress(vehicle_ids, keep)
            deque(map(c.vehicle_setSpeed, ids, compress(speeds, keep)), maxlen=0)

    def move_person(
        self, person_id: str, x: float, y: float, heading: float, edge: str = ""
    ) -> None:
        """Place a person's centre at (``x``, ``y``) facing ``heading`` for the next step."""
        self._commanded((person_id,), persons=True)
        self._placed()
        self._api().person.moveToXY(
            person_id, edge, x, y, angle=heading_to_sumo_angle(heading), keepRoute=2
        )

    # ------------------------------------------------------------------ reads
    def route_of(self, vehicle_id: str) -> tuple[str, ...]:
        """The edge ids of a vehicle's route."""
        return tuple(self._api().vehicle.getRoute(vehicle_id))

    def allowed_speed(self, vehicle_id: str) -> float:
        """The speed limit that applies to the vehicle on its lane, m/s."""
        return float(self._api().vehicle.getAllowedSpeed(vehicle_id))

    def max_accel(self, vehicle_id: str) -> float:
        """The vehicle's own driver's maximum acceleration, m/s^2."""
        return float(self._api().vehicle.getAccel(vehicle_id))

    def next_signal(self, vehicle_id: str) -> NextSignal | None:
        """The next traffic light on the vehicle's route, or None."""
        nxt = self._api().vehicle.getNextTLS(vehicle_id)
        if not nxt:
            return None
        tls, _index, distance, state = nxt[0]
        return NextSignal(tls, float(distance), state)

    def signal_links(self) -> list[SignalLink]:
        """Every controlled link of every traffic light."""
        tl = self._api().trafficlight
        out = []
        for tls in tl.getIDList():
            for idx, links in enumerate(tl.getControlledLinks(tls)):
                for frm, to, via in links:
                    out.append(SignalLink(tls, idx, frm, to, via))
        return out

    def signal_states(self, tls_ids: Sequence[str] | None = None) -> dict[str, str]:
        """Traffic light id -> its state string (one letter per link: r y g G ...)."""
        tl = self._api().trafficlight
        ids = tl.getIDList() if tls_ids is None else tls_ids
        return {t: tl.getRedYellowGreenState(t) for t in ids}

    def set_signal_state(self, tls_id: str, state: str) -> None:
        """Hold traffic light ``tls_id`` at ``state`` (one letter per link: r y g G o O u)."""
        self._api().trafficlight.setRedYellowGreenState(tls_id, state)

    def set_signal_phase(self, tls_id: str, phase: int) -> None:
        """Switch traffic light ``tls_id`` to phase ``phase`` of its program (it runs on from
        there)."""
        self._api().trafficlight.setPhase(tls_id, phase)

    def signal_phases(self, tls_id: str) -> list[str]:
        """The names of the phases of ``tls_id``'s current program ('' where unnamed)."""
        tl = self._api().trafficlight
        prog = tl.getProgram(tls_id)
        logic = next(x for x in tl.getAllProgramLogics(tls_id) if x.programID == prog)
        return [p.name for p in logic.phases]

    def signal_phase(self, tls_id: str) -> int:
        """The index of ``tls_id``'s current phase."""
        return int(self._api().trafficlight.getPhase(tls_id))

    def lane_speed(self, lane_id: str) -> float:
        """The speed limit of SUMO lane ``lane_id``, m/s."""
        return float(self._api().lane.getMaxSpeed(lane_id))

    def lane_allows(self, lane_id: str, vclass: str) -> bool:
        """Whether SUMO lane ``lane_id`` admits vehicles of class ``vclass``."""
        lane = self._api().lane
        allowed, disallowed = lane.getAllowed(lane_id), lane.getDisallowed(lane_id)
        return (not allowed or vclass in allowed) and vclass not in disallowed

    def pending_vehicles(self) -> int:
        """Vehicles waiting to be inserted (no room yet)."""
        return len(self._api().simulation.getPendingVehicles())

    def sumo_reading(self, actor_id: str, is_person: bool) -> SumoReading:
        """The actor through SUMO's plain per-object getters (slow; for checks)."""
        s = self._api()
        dom = s.person if is_person else s.vehicle
        return SumoReading(
            front=tuple(dom.getPosition3D(actor_id)),
            angle=dom.getAngle(actor_id),
            speed=dom.getSpeed(actor_id),
            accel=math.nan if is_person else s.vehicle.getAcceleration(actor_id),
            length=dom.getLength(actor_id),
            width=dom.getWidth(actor_id),
            height=dom.getHeight(actor_id),
            lane=dom.getLaneID(actor_id),
            edge=dom.getRoadID(actor_id),
        )

    def vehicle_ids(self) -> tuple[str, ...]:
        """Ids of the vehicles in the simulation now (cheaper than a WorldState read)."""
        return tuple(self._api().vehicle.getIDList())

    # ------------------------------------------------------------------ road coordinates
    def road_position(self, x: float, y: float) -> tuple[str, float, int]:
        """SUMO's own map matching of a network point: (edge id, position along the lane m,
        lane index), ignoring vehicle-class permissions."""
        edge, pos, lane = self._api().simulation.convertRoad(x, y, False, "ignoring")
        return str(edge), float(pos), int(lane)

    def lane_point(self, edge: str, pos: float, lane_index: int) -> tuple[float, float]:
        """SUMO's network x, y of position ``pos`` m along lane ``lane_index`` of ``edge``."""
        x, y = self._api().simulation.convert2D(edge, pos, lane_index)
        return float(x), float(y)

    def lane_position(self, vehicle_id: str) -> tuple[str, float, float]:
        """Where SUMO has a vehicle: (lane id, front position along it m, lateral offset of its
        centre from the lane's centre line m, left positive)."""
        v = self._api().vehicle
        return (
            v.getLaneID(vehicle_id),
            float(v.getLanePosition(vehicle_id)),
            float(v.getLateralLanePosition(vehicle_id)),
        )
