"""WorldState: every traffic participant at one simulation time, as numpy arrays.

Frames and units: SUMO network coordinates in metres (x east, y north, z up); ``xyz`` is the
centre of the actor's ground rectangle (SUMO reports the front bumper; converted once when
read); ``heading`` in radians counter-clockwise from +x, in (-pi, pi]; speeds in m/s,
acceleration in m/s^2 along the heading; sizes in metres. Time in seconds of simulation time.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from hiyari.errors import HiyariError
from hiyari.kinematics import Pose, footprint_corners, heading_vector
from hiyari.traffic.actor_class import ActorClass


@dataclass(frozen=True, eq=False)
class WorldState:
    """All vehicles and persons at one time step (N actors, vehicles first, then persons)."""

    time: float
    ids: np.ndarray  # (N,) object: SUMO ids
    cls: np.ndarray  # (N,) int8: ActorClass
    xyz: np.ndarray  # (N, 3) float64: ground-rectangle centre, metres
    heading: np.ndarray  # (N,) float64: radians CCW from +x
    speed: np.ndarray  # (N,) float64: m/s
    accel: np.ndarray  # (N,) float64: m/s^2
    length: np.ndarray  # (N,) float64: m
    width: np.ndarray  # (N,) float64: m
    height: np.ndarray  # (N,) float64: m
    lane: np.ndarray  # (N,) object: SUMO lane id ('' when not on a lane)
    edge: np.ndarray  # (N,) object: SUMO edge id

    def __len__(self) -> int:
        return len(self.ids)

    @property
    def is_pedestrian(self) -> np.ndarray:
        """(N,) bool: persons."""
        return self.cls == ActorClass.PEDESTRIAN

    @property
    def is_vehicle(self) -> np.ndarray:
        """(N,) bool: everything that is not a person."""
        return self.cls != ActorClass.PEDESTRIAN

    @property
    def velocity(self) -> np.ndarray:
        """(N, 2) float64: velocity in the network frame, m/s."""
        return self.speed[:, None] * heading_vector(self.heading)

    def pose(self, row: int) -> Pose:
        """The kinematic state of the actor at ``row`` (position, heading, speed, accel, size)."""
        return Pose(
            float(self.xyz[row, 0]),
            float(self.xyz[row, 1]),
            float(self.xyz[row, 2]),
            float(self.heading[row]),
            float(self.speed[row]),
            float(self.accel[row]),
            float(self.length[row]),
            float(self.width[row]),
        )

    def pose_of(self, actor_id: str) -> Pose:
        """The pose of ``actor_id``; HiyariError when it is not in this state."""
        try:
            return self.pose(self.index(actor_id))
        except KeyError:
            raise HiyariError(
                f"actor {actor_id!r} is not in the WorldState at t={self.time} s"
            ) from None

    def index(self, actor_id: str) -> int:
        """Row of ``actor_id``; KeyError when absent."""
        return self._row_of[actor_id]

    def rows(self, actor_ids: Iterable[str]) -> np.ndarray:
        """(K,) int64 row of each of ``actor_ids``, -1 where absent."""
        row_of = self._row_of
        return np.array([row_of.get(a, -1) for a in actor_ids], np.int64)

    @cached_property
    def _row_of(self) -> dict[str, int]:
        """Id -> row, built on first use (a state is looked up many times per step); the
        first row of an id that occurs twice, as a scan would find it."""
        return {a: k for k, a in reversed(list(enumerate(self.ids.tolist())))}

    def select(self, mask: np.ndarray) -> WorldState:
        """A WorldState with only the rows where ``mask`` (bool or index array) selects."""
        return WorldState(
            time=self.time,
            ids=self.ids[mask],
            cls=self.cls[mask],
            xyz=self.xyz[mask],
            heading=self.heading[mask],
            speed=self.speed[mask],
            accel=self.accel[mask],
            length=self.length[mask],
            width=self.width[mask],
            height=self.height[mask],
            lane=self.lane[mask],
            edge=self.edge[mask],
        )

    def corners(self) -> np.ndarray:
        """(N, 4, 2) ground-rectangle corners, counter-clockwise from front-left, metres."""
        return footprint_corners(self.xyz[:, :2], self.heading, self.length, self.width)

    def same_as(self, other: WorldState) -> bool:
        """True when both states are equal bit for bit (ids, classes, every float)."""
        arrays = ("ids", "cls", "xyz", "heading", "speed", "accel", "length", "width", "height")
        return (
            self.time == other.time
            and all(np.array_equal(getattr(self, a), getattr(other, a)) for a in arrays)
            and np.array_equal(self.lane, other.lane)
            and np.array_equal(self.edge, other.edge)
        )

    @staticmethod
    def empty(time: float = 0.0) -> WorldState:
        """A state with no actors."""
        f = np.zeros(0)
        o = np.zeros(0, dtype=object)
        return WorldState(time, o, np.zeros(0, np.int8), np.zeros((0, 3)), f, f, f, f, f, f, o, o)
