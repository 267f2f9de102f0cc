"""The ego stack: perception -> fusion -> planner (ACC + AEB). Each part is replaceable.

A user plugs in their own part by passing any object with the same method (``perceive``,
``update`` or ``plan``), or a whole stack class named in the scenario file (``ego.stack =
"my_module:MyStack"``) whose constructor takes the ConcreteScenario.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from hiyari.bridge.loop.stack.aeb import EgoCommand
from hiyari.kinematics import Pose
from hiyari.sensors.outputs import ObjectList
from hiyari.traffic.world_state import WorldState


class Perception(Protocol):
    """Sensors + recognition: object lists of this step (empty list when no sensor is due)."""

    def perceive(self, world: WorldState, ego_row: int, ego: Pose) -> list[ObjectList]: ...


class Fusion(Protocol):
    """Object lists -> tracks (ObjectList in the ego frame, velocities relative to the ego)."""

    def update(self, lists: list[ObjectList], ego: Pose, time: float) -> ObjectList: ...


class Planner(Protocol):
    """Tracks -> the ego's acceleration command."""

    def plan(self, tracks: ObjectList, ego: Pose, time: float) -> EgoCommand: ...


@dataclass
class EgoStep:
    """Everything the stack produced at one step (for metrics and recording)."""

    command: EgoCommand
    object_lists: list[ObjectList]
    tracks: ObjectList


@dataclass
class EgoStack:
    """Perception, fusion and planner run in sequence each step."""

    perception: Perception
    fusion: Fusion
    planner: Planner

    def step(self, world: WorldState, ego_row: int) -> EgoStep:
        """Run the stack on this step's WorldState; ``ego_row`` is the ego's row in it."""
        ego = world.pose(ego_row)
        lists = self.perception.perceive(world, ego_row, ego)
        tracks = self.fusion.update(lists, ego, world.time)
        return EgoStep(self.planner.plan(tracks, ego, world.time), lists, tracks)
