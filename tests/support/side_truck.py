"""A truck passing beside the ego, seen by the default sensor rig on a hand-built road (no SUMO).

The layouts are the blind-spot set's with the truck beside the ego (occluder positions 4 and 7,
bridge/studies/perception/blindspot/catalogue.py): the truck in the lane right or left of the
ego's, and the hidden car ahead in the ego's lane, just ahead of where the truck's front ends,
or in the truck's lane ahead of it. Unlike the blind-spot runs (every vehicle at 80 km/h), the
truck passes at ``relative`` m/s, so its whole side slides past the roof LiDAR. Everything
moves on straight lines at constant speed (open loop: the ego's planner is run but does not
move the ego), so a run is a few seconds of ray casts and the same bit for bit every time.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from hiyari.bridge.loop.stack.aeb import ACCConfig, AEBPlanner
from hiyari.bridge.loop.stack.fusion import KalmanFusion
from hiyari.bridge.loop.stack.perception_sensors import SensorPerception
from hiyari.sensors.environment.presets import disturbance_preset
from hiyari.sensors.rig import SensorRig
from hiyari.sensors.scene.ray_scene import RayScene
from hiyari.sensors.scene.synthetic import StraightRoad, actor_world
from hiyari.traffic.actor_class import ActorClass
from hiyari.units import kmh_to_mps

LANE = 3.5
EGO_SPEED = float(kmh_to_mps(80.0))
STEP = 0.05

#: layout name -> (truck lane offset, + left; hidden car (lane offset, x ahead of the ego m) or
#: None)
LAYOUTS: dict[str, tuple[int, tuple[int, float] | None]] = {
    "truck right, car ahead in the ego lane": (-1, (0, 9.5)),
    "truck left, car ahead in the ego lane": (1, (0, 9.5)),
    "truck right, car ahead in its lane": (-1, (-1, 14.0)),
}


@dataclass
class SideRun:
    """What the stack made of the truck, step by step."""

    lateral_error: list[float] = field(default_factory=list)
    """|lateral velocity| (m/s) of every truck track the planner acts on (its truth moves
    straight along the road: 0 m/s sideways), every step."""
    stages: list[int] = field(default_factory=list)
    """AEB stage decided at every step."""


def run_side_truck(
    layout: str, relative: float = float(kmh_to_mps(20.0)), seconds: float = 3.0, seed: int = 1
) -> SideRun:
    """The truck starts with its front 6 m behind the ego's centre and overtakes at
    ``relative`` m/s; the ego drives at 80 km/h in the middle of three lanes."""
    truck_lane, car = LAYOUTS[layout]
    scene = RayScene(StraightRoad(x0=-60.0, x1=160.0, lanes=3, buildings=False).mesh())
    perception = SensorPerception(
        scene, SensorRig.default(), disturbance_preset("clear"), "ego", STEP, seed
    )
    fusion = KalmanFusion()
    planner = AEBPlanner(ACCConfig(set_speed=EGO_SPEED, follow=False))
    truck_len = ActorClass.TRUCK.size.length
    out = SideRun()
    for k in range(1, int(round(seconds / STEP)) + 1):
        t = k * STEP
        ego_x = EGO_SPEED * t
        actors = [
            dict(id="ego", cls=ActorClass.CAR, x=ego_x, y=0.0, speed=EGO_SPEED),
            dict(
                id="truck",
                cls=ActorClass.TRUCK,
                x=ego_x - 6.0 - truck_len / 2 + relative * t,
                y=truck_lane * LANE,
                speed=EGO_SPEED + relative,
            ),
        ]
        if car is not None:
            lane, ahead = car
            actors.append(
                dict(id="car", cls=ActorClass.CAR, x=ego_x + ahead, y=lane * LANE, speed=EGO_SPEED)
            )
        world = actor_world(actors, time=t)
        ego = world.pose(0)
        lists = perception.perceive(world, 0, ego)
        tracks = fusion.update(lists, ego, t)
        command = planner.plan(tracks, ego, t)
        out.stages.append(int(command.aeb_stage))
        acted = (tracks.truth == "truck") & (tracks.cls >= 0)
        if tracks.velocity_sigma is not None:
            acted &= tracks.velocity_sigma <= planner.aeb.max_velocity_sigma
        out.lateral_error += [abs(float(v)) for v in tracks.velocity[acted, 1]]
    return out
