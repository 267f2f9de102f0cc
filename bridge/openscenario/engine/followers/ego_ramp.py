"""The Init speed ramp of a stack-driven ego.

An Init SpeedAction with a transition (not ``step``) sets the ego's initial condition over
time: the ego goes from its Init speed to the action's target as the transition says, and
the target is the speed its stack then keeps (the ACC set speed). While the ramp runs its
speed is the ego's command, unless the stack slows the ego (AEB or following): the stack
then has the ego and the ramp ends.
"""

from __future__ import annotations

from dataclasses import dataclass

from hiyari.bridge.openscenario.engine.kernels.shapes import progress
from hiyari.bridge.openscenario.model.actions import Shape


@dataclass
class EgoRamp:
    """From ``v0`` to ``goal`` (m/s) with ``shape`` over ``span`` seconds (``by_distance``:
    metres travelled), from scenario time 0."""

    v0: float
    goal: float
    shape: Shape
    span: float
    by_distance: bool
    done: float = 0.0  # seconds elapsed or metres travelled so far
    over: bool = False

    def command(self, stack_speed: float, speed_now: float, dt: float) -> float:
        """The ego's speed (m/s) at the end of the coming ``dt`` s: the ramp's, or
        ``stack_speed`` once the stack commands less than ``speed_now`` (it brakes)."""
        if self.over:
            return stack_speed
        if stack_speed < speed_now - 1e-9:
            self.over = True
            return stack_speed
        self.done += speed_now * dt if self.by_distance else dt
        x = self.done / self.span
        if x >= 1.0 - 1e-9:
            self.over = True
            return self.goal
        return self.v0 + (self.goal - self.v0) * progress(self.shape, x)
