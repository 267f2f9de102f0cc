"""Starting, finishing and cancelling storyboard actions on actors.

Each started action is an Instance on one actor. Motion actions claim the actor's
longitudinal and / or lateral domain; a new claim stops the action holding it (OpenSCENARIO:
a new action of the same kind overrides the running one).
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from hiyari.bridge.openscenario.engine.followers.ego_ramp import EgoRamp
from hiyari.bridge.openscenario.engine.followers.lateral_distance import (
    lateral_goal,
    limited,
    next_lateral_speed,
    sinusoidal_duration,
)
from hiyari.bridge.openscenario.engine.followers.speed_profile import (
    JerkLimited,
    speed_profile,
)
from hiyari.bridge.openscenario.engine.followers.synchronize import Synchronizer
from hiyari.bridge.openscenario.engine.frames.gap import gap_s, ref_length
from hiyari.bridge.openscenario.engine.frames.links import road_ahead, walk
from hiyari.bridge.openscenario.engine.global_actions import is_global, run_global
from hiyari.bridge.openscenario.engine.kernels import motion_kernel as MK
from hiyari.bridge.openscenario.engine.kernels.shapes import lateral_duration, span
from hiyari.bridge.openscenario.engine.motion import (
    Actor,
    LateralTransition,
    PathMotion,
    SpeedTransition,
    end_long,
    forward,
    place_actor,
    read_targets,
)
from hiyari.bridge.openscenario.engine.paths.route import random_destination
from hiyari.bridge.openscenario.engine.paths.sampled import SampledPath
from hiyari.bridge.openscenario.engine.positions import Pose, lane_shift
from hiyari.bridge.openscenario.model.actions import (
    AbsoluteLane,
    AbsoluteOffset,
    AbsoluteSpeed,
    AcquirePositionAction,
    Action,
    ActivateControllerAction,
    AssignControllerAction,
    AssignRouteAction,
    Dimension,
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LateralDistanceAction,
    LightStateAction,
    LongitudinalDistanceAction,
    RandomRouteAction,
    Shape,
    SpeedAction,
    SpeedProfileAction,
    SynchronizeAction,
    TeleportAction,
    VisibilityAction,
)
from hiyari.bridge.openscenario.model.entities import EntityKind
from hiyari.bridge.openscenario.model.positions import LanePosition, WorldPosition
from hiyari.bridge.openscenario.model.trajectories import Route
from hiyari.errors import HiyariError

if TYPE_CHECKING:
    from hiyari.bridge.openscenario.engine.executor import ScenarioEngine

_MOTION = (
    SpeedAction,
    RandomRouteAction,
    SpeedProfileAction,
    LateralDistanceAction,
    SynchronizeAction,
    LongitudinalDistanceAction,
    LaneChangeAction,
    LaneOffsetAction,
    TeleportAction,
    FollowTrajectoryAction,
    AssignRouteAction,
    AcquirePositionAction,
)


#: The distance follower's spring constant per unit of its acceleration limit (1/m) and its
#: limit when none is given (m/s^2); the gap and speed difference that count as reached.
GAP_SPRING, GAP_TENSION, GAP_REACHED = 0.4, 5.0, 0.1


@dataclass
class Instance:
    """One action running on one actor; ``obj`` is the transition or path it installed."""

    element: int
    actor: str
    domains: tuple[str, ...]
    obj: object = None
    finished: bool = False
    until: Callable[[], bool] | None = None  # for an action that ends itself: whether it has


class ActionStarter:
    """Applies actions to the engine's actors."""

    def __init__(self, engine: ScenarioEngine) -> None:
        self.e = engine

    # ------------------------------------------------------------------ lifecycle
    def start(self, element: int, action: Action, actor: str, now: float, init: bool) -> Instance:
        """Start ``action`` on ``actor`` at scenario time ``now``."""
        body = action.body
        eng = self.e
        if is_global(body):
            run_global(eng, body, action.source or action.name)
            return Instance(element, actor, (), finished=True)
        if isinstance(body, AssignControllerAction | ActivateControllerAction):
            try:
                self._controller(actor, body)
            except HiyariError as exc:
                raise HiyariError(f"{action.source or action.name}: {exc}") from None
            return Instance(element, actor, (), finished=True)
        if isinstance(body, VisibilityAction):
            eng.visibility[actor] = body
            return Instance(element, actor, (), finished=True)
        if isinstance(body, LightStateAction):
            eng.set_light(actor, body)
            return Instance(element, actor, (), finished=True)
        if isinstance(body, FollowTrajectoryAction) and not eng.storyboard_drives(actor):
            return self._ego_trajectory(element, eng.actors[actor], body, now)
        initial_pose = init and isinstance(body, TeleportAction | SpeedAction) and _instant(body)
        if init and isinstance(body, SpeedAction) and not eng.storyboard_drives(actor):
            if not initial_pose:  # the ego ramps to the target, the stack then keeps it
                eng.ego_ramp = self._ego_ramp(eng.actors[actor], body, action)
                return Instance(element, actor, (), finished=True)
        if isinstance(body, _MOTION) and not eng.storyboard_drives(actor) and not initial_pose:
            eng._ego_requests.append(action.name)
            return Instance(element, actor, (), finished=True)
        a = eng.actors[actor]
        try:
            return self._motion(element, a, body, now)
        except HiyariError as exc:
            raise HiyariError(f"{action.source or action.name}: {exc}") from None

    def done(self, inst: Instance) -> bool:
        """Whether the instance has finished (its transition or path is over)."""
        if inst.finished:
            return True
        a = self.e.actors[inst.actor]
        if inst.until is not None and inst.until():
            if a.long is inst.obj:
                a.long = None
            inst.finished = True
            return True
        if any(self.e.keepers.get((inst.actor, d)) is inst.obj for d in inst.domains):
            return False  # a continuous action holding its goal runs until it is stopped
        if inst.obj is not None and inst.obj not in (a.long, a.lat, a.path):
            inst.finished = True
        return inst.finished

    def cancel(self, inst: Instance) -> None:
        """Stop the instance: remove what it installed from its actor."""
        a = self.e.actors[inst.actor]
        if inst.obj is a.long:
            a.long = None
        if inst.obj is a.lat:
            a.lat = None
        if inst.obj is a.path:
            a.path = None
        for d in inst.domains:
            if inst.obj is not None and self.e.keepers.get((inst.actor, d)) is inst.obj:
                del self.e.keepers[(inst.actor, d)]
        for d in inst.domains:
            self.e.owner.pop((inst.actor, d), None)
        inst.finished = True

    def _claim(self, element: int, actor: str, domains: tuple[str, ...]) -> None:
        for d in domains:
            holder = self.e.owner.get((actor, d))
            if holder is not None and holder != element and holder in self.e.instances:
                self.e._stop(holder)
            self.e.owner[(actor, d)] = element

    def _controller(
        self, actor: str, body: AssignControllerAction | ActivateControllerAction
    ) -> None:
        doms = self.e.active_domains[actor]
        was = self.e.storyboard_drives(actor)
        here = (
            None
            if was or self.e._world is None
            else (self.e.pose_of(actor), self.e.speed_of(actor))
        )
        if isinstance(body, AssignControllerAction):
            self.e.controller[actor] = body.controller
        elif body.controller is not None:
            known = self.e.actors[actor].entity.controllers
            if body.controller not in known:
                raise HiyariError(
                    f"ActivateControllerAction: entity {actor!r} has no controller "
                    f"{body.controller!r} (its controllers: {', '.join(known) or 'none'})"
                )
            self.e.controller[actor] = known[body.controller]
        if body.lateral is not None:
            doms["lateral"] = body.lateral
        if body.longitudinal is not None:
            doms["longitudinal"] = body.longitudinal
        if here is not None and self.e.storyboard_drives(actor):
            # the storyboard takes the ego over where the stack left it
            a = self.e.actors[actor]
            self._teleport(a, here[0])
            a.v = here[1]

    # ------------------------------------------------------------------ motion actions
    def _motion(self, element: int, a: Actor, body: object, now: float) -> Instance:
        if isinstance(body, TeleportAction):
            self._teleport(a, self.e.resolver.resolve(body.position))
            return Instance(element, a.name, (), finished=True)
        if isinstance(body, SpeedAction):
            return self._speed(element, a, body, now)
        if isinstance(body, SpeedProfileAction):
            return self._speed_profile(element, a, body, now)
        if isinstance(body, SynchronizeAction):
            sync = Synchronizer(self.e, a.name, body)
            self._claim(element, a.name, ("longitudinal",))
            tr = SpeedTransition(a.v, a.v, sync.goal, Shape.STEP, 0.0, False, True, now)
            a.long, a.long_travelled = tr, 0.0
            return Instance(element, a.name, ("longitudinal",), tr, until=lambda: sync.done)
        if isinstance(body, LongitudinalDistanceAction) and body.limits is not None:
            return self._gap_follower(element, a, body, now)
        if isinstance(body, LongitudinalDistanceAction):
            self._claim(element, a.name, ("longitudinal",))
            self._gap(a, body)
            if not body.continuous:
                return Instance(element, a.name, ("longitudinal",), finished=True)

            def keep() -> None:
                self._gap(a, body)
                a.v = self.e.speed_of(body.entity)

            a.long = None
            self.e.keepers[(a.name, "longitudinal")] = keep
            return Instance(element, a.name, ("longitudinal",), keep)
        if isinstance(body, LateralDistanceAction):
            return self._lateral_distance(element, a, body, now)
        if isinstance(body, LaneChangeAction):
            return self._lane_change(element, a, body, now)
        if isinstance(body, LaneOffsetAction):
            return self._lane_offset(element, a, body, now)
        if isinstance(body, FollowTrajectoryAction):
            return self._trajectory(element, a, body, now)
        if isinstance(body, AssignRouteAction):
            return self._route(element, a, body.route)
        if isinstance(body, RandomRouteAction):
            return self._route(element, a, self._random_route(a))
        here = WorldPosition(a.x, a.y, a.z, a.h)
        return self._route(element, a, Route("AcquirePositionAction", (here, body.position)))

    def place(self, a: Actor, p: Pose) -> None:
        """Put ``a`` at ``p`` (on its road when ``p`` is on one)."""
        self._teleport(a, p)

    def _teleport(self, a: Actor, p: Pose) -> None:
        a.x, a.y, a.z, a.h = p.x, p.y, p.z, p.h
        a.path, a.lat = None, None
        if p.road:
            a.road, a.lane, a.s, a.t, a.free = p.road, p.lane, p.s, p.t, False
            # facing more than a right angle off its lane's direction: it drives the other way
            lane_h = self._lane_heading(a)
            h_rel = math.remainder(p.h - lane_h, 2 * math.pi)
            a.against = abs(h_rel) > math.pi / 2 + 1e-9
            a.h_rel = math.remainder(h_rel - math.pi, 2 * math.pi) if a.against else h_rel
        else:
            a.free = True

    def _lane_heading(self, a: Actor) -> float:
        """Heading of ``a``'s lane's driving direction at its s (rad)."""
        odr = self.e.roads.odr
        h = float(odr.road(a.road).reference(np.array([a.s]))[2][0])
        return h if forward(odr, a.road, a.lane) > 0 else h + math.pi

    def _ego_ramp(self, a: Actor, body: SpeedAction, action: Action) -> EgoRamp:
        """The Init ramp of the stack-driven ego ``a``: to the target as resolved now."""
        dyn = body.dynamics
        goal = self._speed_goal(body)
        where = action.source or action.name
        length = span(dyn.shape, dyn.dimension, dyn.value, goal - a.v, where)
        # the stack drives forwards: a backing ego (negative speed) ramps its magnitude
        v0, goal = abs(a.v), abs(goal)
        return EgoRamp(v0, goal, dyn.shape, length, dyn.dimension == Dimension.DISTANCE)

    def _speed_goal(self, body: SpeedAction) -> float:
        """The target speed of ``body`` now (m/s): absolute, or relative to its entity."""
        tgt = body.target
        if isinstance(tgt, AbsoluteSpeed):
            return tgt.value
        at_start = self.e.speed_of(tgt.entity)
        return at_start * tgt.value if tgt.kind == "factor" else at_start + tgt.value

    def _speed(self, element: int, a: Actor, body: SpeedAction, now: float) -> Instance:
        tgt = body.target
        follow: Callable[[], float] | None = None
        goal = self._speed_goal(body)
        if not isinstance(tgt, AbsoluteSpeed):
            ref, value, factor = tgt.entity, tgt.value, tgt.kind == "factor"
            if tgt.continuous:

                def follow() -> float:
                    base = self.e.speed_of(ref)
                    return base * value if factor else base + value

        dyn = body.dynamics
        continuous = follow is not None
        change = goal - a.v
        length = span(dyn.shape, dyn.dimension, dyn.value, change, "SpeedAction")
        self._claim(element, a.name, ("longitudinal",))
        if length == 0.0 and not continuous:
            a.v, a.long = goal, None
            return Instance(element, a.name, ("longitudinal",), finished=True)
        tr = SpeedTransition(
            a.v, goal, follow, dyn.shape, length, dyn.dimension == Dimension.DISTANCE,
            continuous, now,
        )  # fmt: skip
        a.long, a.long_travelled = tr, 0.0
        return Instance(element, a.name, ("longitudinal",), tr)

    def _speed_profile(
        self, element: int, a: Actor, body: SpeedProfileAction, now: float
    ) -> Instance:
        base = self.e.speed_of(body.entity) if body.entity else 0.0
        times, speeds = speed_profile(body, a.v, base, now)
        over = [False]
        jerk = None
        if body.following_mode == "follow" and (body.max_accel_rate or body.max_decel_rate):
            jerk = JerkLimited.of(body, times, speeds)
            # from the actor's acceleration, within the action's limits
            jerk.acc = min(body.max_accel or math.inf, max(-(body.max_decel or math.inf), a.accel))

        def goal() -> float:
            t = self.e.now + self.e.dt  # the speed at the end of the coming step
            if jerk is not None:
                jerk.v = a.v
                v = jerk.step(self.e.dt)
                done = jerk.reached()
            else:
                v, done = float(np.interp(t, times, speeds)), t >= times[-1] - 1e-9
            if done and not over[0]:
                over[0] = True
                self.e.table.motion_version += 1  # the storyboard is to end the action
            return v

        self._claim(element, a.name, ("longitudinal",))
        tr = SpeedTransition(a.v, a.v, goal, Shape.STEP, 0.0, False, True, now)
        a.long, a.long_travelled = tr, 0.0
        return Instance(element, a.name, ("longitudinal",), tr, until=lambda: over[0])

    def _gap_follower(
        self, element: int, a: Actor, body: LongitudinalDistanceAction, now: float
    ) -> Instance:
        """Drive to the gap (and hold it when continuous) as a critically damped spring on
        the gap's error and the speed difference, within the DynamicConstraints."""
        max_acc, max_dec, max_speed = body.limits
        done = [False]

        def goal() -> float:
            error = self._gap_error(a, body)  # m short of where the gap puts the actor
            dv = self.e.speed_of(body.entity) - a.v
            tension = (max_acc if error > 0 else max_dec) or GAP_TENSION
            k = GAP_SPRING * tension
            acc = k * error + 2.0 * math.sqrt(k) * dv
            acc = min(acc, max_acc) if max_acc else acc
            acc = max(acc, -max_dec) if max_dec else acc
            v = max(0.0, a.v + acc * self.e.dt)
            if max_speed is not None:
                v = min(v, max_speed)
            if not body.continuous and abs(error) < GAP_REACHED and abs(dv) < GAP_REACHED:
                if not done[0]:
                    done[0] = True
                    self.e.table.motion_version += 1
            return v

        self._claim(element, a.name, ("longitudinal",))
        tr = SpeedTransition(a.v, a.v, goal, Shape.STEP, 0.0, False, True, now)
        a.long, a.long_travelled = tr, 0.0
        return Instance(element, a.name, ("longitudinal",), tr, until=lambda: done[0])

    def _gap_error(self, a: Actor, body: LongitudinalDistanceAction) -> float:
        """Metres ``a`` is short of its gap position along the road (negative: past it)."""
        s_now, road, lane = a.s, a.road, a.lane
        direction = self.e.travel_direction(a.name)
        self._gap(a, body, place=False)
        goal_road, goal_s = a.road, a.s
        a.s, a.road, a.lane = s_now, road, lane
        return road_ahead(self.e.resolver.graph(), road, s_now, direction, goal_road, goal_s)

    def _gap(self, a: Actor, body: LongitudinalDistanceAction, place: bool = True) -> None:
        ref, road = self.e.pose_of(body.entity), a.road
        if not ref.road or not a.road:
            raise HiyariError("LongitudinalDistanceAction needs both entities on a road")
        gap = (
            body.distance
            if body.distance is not None
            else body.time_gap * self.e.speed_of(body.entity)
        )
        ent_ref = self.e.actors[body.entity].entity
        direction = self.e.travel_direction(body.entity)
        cx_r, cx_a = ent_ref.centre[0], a.entity.centre[0]
        trailing = body.displacement == "trailingReferencedEntity" or (
            # any: on the side of the reference it is on (behind it when level or on
            # another road)
            body.displacement == "any" and (a.road != ref.road or (a.s - ref.s) * direction <= 0.0)
        )
        if trailing:
            lead = (
                -(gap + (cx_a + a.entity.length / 2) - (cx_r - ent_ref.length / 2))
                if body.freespace
                else -gap
            )
        else:
            lead = (
                (gap + (cx_r + ent_ref.length / 2) - (cx_a - a.entity.length / 2))
                if body.freespace
                else gap
            )
        a.road, a.s = ref.road, ref.s + direction * lead
        if (
            body.coordinate_system != "road"
            and a.s == a.s
            and 0.0 <= a.s <= ref_length(self.e, ref)
        ):
            a.s = gap_s(self.e, ref, a, direction * lead, body.coordinate_system)
        if not 0.0 <= a.s <= self.e.roads.odr.road(ref.road).length:
            # past the reference's road end: on along the road links (towards the road the
            # actor is on, at a junction)
            graph = self.e.resolver.graph()
            a.road, a.s, way = walk(graph, ref.road, ref.s, int(direction), lead, road)
            if way != direction:  # entered at its end: the lane on the same side has the
                a.lane = -a.lane  # other sign
        if place:
            place_actor(self.e.roads.odr, a)

    def _lateral_distance(
        self, element: int, a: Actor, body: LateralDistanceAction, now: float
    ) -> Instance:
        """Without DynamicConstraints the actor is put at its goal (and held there every step
        when continuous). With them it moves there within the limits: not continuous, in the
        sinusoidal move they allow; continuous, following the (possibly moving) goal step by
        step (``next_lateral_speed``), the lateral share of its path taken out of its progress
        along the road as in the motion kernel (its speed is the speed along its path)."""
        if a.free or not a.road:
            raise HiyariError(f"LateralDistanceAction on {a.name!r}, which is not on a road")
        goal = lateral_goal(self.e, a.name, body)
        if body.continuous:
            v_lat = [0.0]
            odr = self.e.roads.odr

            def keep() -> None:
                target = lateral_goal(self.e, a.name, body)
                if limited(body):
                    v_lat[0] = next_lateral_speed(target - a.t, v_lat[0], self.e.dt, body)
                    d_lat, d = v_lat[0] * self.e.dt, float(a.table.step_travelled[a.k])
                    back = abs(d) - math.sqrt(max(0.0, d * d - d_lat * d_lat))
                    curve = max(1e-3, 1.0 - float(a.table.kappa[a.k]) * a.t)
                    a.s -= float(a.table.direction[a.k]) * math.copysign(back, d) / curve
                    a.t, a.v_lat = a.t + d_lat, v_lat[0]
                else:
                    a.t = target
                a.lane = self.e.resolver.at_road(a.road, a.s, a.t).lane
                place_actor(odr, a)

            self._claim(element, a.name, ("lateral",))
            a.lat = None
            if not limited(body):
                keep()
            self.e.keepers[(a.name, "lateral")] = keep
            return Instance(element, a.name, ("lateral",), keep)
        lane = self.e.resolver.at_road(a.road, a.s, goal).lane
        offset = goal - self._lane_t(a.road, lane, a.s)
        duration = sinusoidal_duration(body, goal - a.t) if limited(body) else 0.0
        shape = Shape.SINUSOIDAL if duration > 0 else Shape.STEP
        return self._lateral(
            element, a, lane, offset, None, shape, Dimension.TIME, duration, now, False
        )

    def _lane_change(self, element: int, a: Actor, body: LaneChangeAction, now: float) -> Instance:
        if isinstance(body.target, AbsoluteLane):
            lane = body.target.lane
        else:
            ref = self.e.pose_of(body.target.entity)
            direction = forward(self.e.roads.odr, ref.road, ref.lane)
            lane = lane_shift(ref.lane, int(direction) * body.target.value)
        dyn = body.dynamics
        return self._lateral(
            element, a, lane, body.target_offset, None, dyn.shape, dyn.dimension, dyn.value, now,
            False,
        )  # fmt: skip

    def _lane_offset(self, element: int, a: Actor, body: LaneOffsetAction, now: float) -> Instance:
        tgt = body.target

        def offset() -> float:
            if isinstance(tgt, AbsoluteOffset):
                return tgt.value
            ref = self.e.pose_of(tgt.entity)
            return ref.t - self.e.roads.odr.road(ref.road).lane_t(ref.lane, ref.s) + tgt.value

        fixed = offset()
        follow = offset if body.continuous else None
        change = self._lane_t(a.road, a.lane, a.s) + fixed - a.t
        duration = lateral_duration(body.shape, body.max_lateral_acc, change)
        return self._lateral(
            element, a, a.lane, fixed, follow, body.shape, Dimension.TIME, duration, now,
            body.continuous,
        )  # fmt: skip

    def _lane_t(self, road: str, lane: int, s: float) -> float:
        return self.e.roads.odr.road(road).lane_t(lane, s)

    def _lateral(
        self,
        element: int,
        a: Actor,
        lane: int,
        offset: float,
        follow: Callable[[], float] | None,
        shape: Shape,
        dimension: Dimension,
        value: float,
        now: float,
        continuous: bool,
    ) -> Instance:
        if a.free or not a.road:
            raise HiyariError(f"lateral action on {a.name!r}, which is not on a road")
        goal = self._lane_t(a.road, lane, a.s) + offset
        length = (
            value
            if dimension == Dimension.TIME and shape != Shape.STEP
            else span(shape, dimension, value, goal - a.t, "lateral action")
        )
        self._claim(element, a.name, ("lateral",))
        tr = LateralTransition(
            a.t, a.road, lane, offset, follow, shape, length, dimension == Dimension.DISTANCE,
            continuous, now,
        )  # fmt: skip
        a.lat, a.lat_travelled = tr, 0.0
        if length == 0.0 and not continuous:
            a.t, a.lane, a.lat = goal, lane, None
            place_actor(self.e.roads.odr, a)
            return Instance(element, a.name, ("lateral",), finished=True)
        return Instance(element, a.name, ("lateral",), tr)

    # ------------------------------------------------------------------ paths
    def _trajectory(
        self, element: int, a: Actor, body: FollowTrajectoryAction, now: float
    ) -> Instance:
        start = Pose(a.x, a.y, a.z, a.h, "" if a.free else a.road, a.lane, a.s, a.t)
        path = self.e.resolver.trajectory(body.trajectory, start)
        self.e.trajectory_of[a.name] = path
        times = None
        if body.timing is not None and path.times is not None:
            tm = body.timing
            base = 0.0 if tm.absolute else now
            times = base + tm.scale * path.times + tm.offset
        motion = PathMotion(path, times, False, body.initial_distance_offset, a.v < 0)
        return self._follow(element, a, motion, now)

    def _random_route(self, a: Actor) -> Route:
        """A route from where ``a`` is to a destination drawn along the roads ahead."""
        p = Pose(a.x, a.y, a.z, a.h, "" if a.free else a.road, a.lane, a.s, a.t)
        if not p.road:
            p = self.e.resolver.at_xy(a.x, a.y, a.h)
        if not p.road:
            raise HiyariError(f"RandomRouteAction: {a.name!r} is not on a road")
        direction = int(self.e.travel_direction(a.name))
        rng = np.random.default_rng(zlib.crc32(a.name.encode()))
        road, s, d = random_destination(self.e.resolver.graph(), p.road, p.s, direction, rng)
        lane = -1 if d > 0 else 1  # the first lane in the direction of travel
        return Route(
            "RandomRouteAction", (WorldPosition(a.x, a.y, a.z, a.h), LanePosition(road, lane, s))
        )

    def _ego_trajectory(
        self, element: int, a: Actor, body: FollowTrajectoryAction, now: float
    ) -> Instance:
        """A stack-driven ego steers along the trajectory (its timing is not applied: the
        stack keeps the speed); it starts at the trajectory's start + initial offset."""
        start = Pose(a.x, a.y, a.z, a.h, "" if a.free else a.road, a.lane, a.s, a.t)
        path = self.e.resolver.trajectory(body.trajectory, start)
        self.e.trajectory_of[a.name] = path
        motion = PathMotion(path, None, False, body.initial_distance_offset, a.v < 0)
        a.x, a.y, a.h = motion.start(now)
        a.free = True
        self.e.ego_path = motion
        return Instance(
            element, a.name, (), motion, until=lambda: motion.travelled >= path.length - 1e-9
        )

    def _route(self, element: int, a: Actor, route: Route) -> Instance:
        """Follow ``route`` from where the actor is on it, at its lateral place there (straight
        lines through the waypoints when no road connects them)."""
        odr = self.e.roads.odr
        try:
            legs = self.e.resolver.route(route)
            s0, t0 = legs.sampled(odr, 0.0).project(a.x, a.y)
            path = legs.sampled(odr, t0)
        except HiyariError:
            pts = [[a.x, a.y]] + [[p.x, p.y] for p in map(self.e.resolver.resolve, route.waypoints)]
            path, s0 = SampledPath.through(np.array(pts)), 0.0
        stop = a.entity.kind == EntityKind.PEDESTRIAN
        return self._follow(element, a, PathMotion(path, None, stop, s0, a.v < 0), None)

    def _follow(self, element: int, a: Actor, path: PathMotion, now: float | None) -> Instance:
        """Put ``a`` on ``path``: at its start pose when ``now`` is given (a trajectory places
        its actor), where the actor is otherwise. A timed path holds both domains, an untimed
        one the lateral only (the speed stays the longitudinal actions')."""
        domains = ("longitudinal", "lateral") if path.times is not None else ("lateral",)
        self._claim(element, a.name, domains)
        if path.times is not None:
            a.long = None
        a.lat, a.path, a.free = None, path, True
        if now is not None:
            a.x, a.y, a.h = path.start(now)
        return Instance(element, a.name, domains, path)

    def follow_paths(self, rows: list[int], now: float) -> None:
        """Advance the free actors of table ``rows`` along their paths to scenario time
        ``now``: speeds from their longitudinal transitions (untimed paths) in the motion
        kernel's own pass, then the distance that speed covers along the path."""
        tb = self.e.table
        actors = [self.e._actor_list[k] for k in rows]
        r = np.array(rows, dtype=np.intp)
        read_targets(tb)
        tb.kappa[r] = 0.0
        before = tb.long_travelled[r].copy()
        ended = MK.advance_long(r, now, self.e.dt, tuple(tb.arrays))
        ds = tb.long_travelled[r] - before
        for a, d in zip(actors, ds.tolist(), strict=True):
            if a.path is not None:
                self._along(a, now, d)
        end_long(self.e._actor_list, r, ended)

    def _along(self, a: Actor, now: float, ds: float) -> None:
        path = a.path
        x, y, h, v, done = path.advance(now, ds)
        if v is not None:
            a.accel = (v - a.v) / self.e.dt
            a.v = v
        a.x, a.y, a.h = x, y, h
        if not done:
            return
        a.path = None
        if path.stop_at_end:
            a.accel, a.v = 0.0, 0.0
            return
        # on at its speed, from where the step would have taken it past the end: along the
        # road it ends on, else straight ahead
        odr = self.e.roads.odr
        p = self.e.resolver.at_xy(a.x, a.y, a.h)
        if p.road and abs(p.t - odr.road(p.road).lane_t(p.lane, p.s)) < 2.0:
            self._teleport(a, p)
            if path.beyond > 0.0:
                lane_dir = forward(odr, a.road, a.lane) * (-1.0 if a.against else 1.0)
                a.s += lane_dir * math.copysign(path.beyond, a.v)
                place_actor(odr, a)
            return
        c, s_ = (
            math.cos(path.path.direction(path.path.length)),
            math.sin(path.path.direction(path.path.length)),
        )
        ahead = SampledPath.through(np.array([[a.x, a.y], [a.x + 1e4 * c, a.y + 1e4 * s_]]))
        a.path = PathMotion(ahead, None, False, path.beyond, path.reverse)
        a.x, a.y, a.h = a.path.pose()


def _instant(body: object) -> bool:
    return isinstance(body, TeleportAction) or body.dynamics.shape == Shape.STEP
