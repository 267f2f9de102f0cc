"""An ego stack that brakes fully on a phantom at the start of every run (``ego.stack =
"phantom_stack:phantom_brake"`` with tests/support on the path): what a young fusion track
born at zero ground speed did in 13 of 40 R157 cut-in points (issue 30). The ego stops
before the manoeuvre starts, so the run must be "not tested", never a pass."""

from __future__ import annotations

from dataclasses import replace

from hiyari.bridge.loop.spec import StackContext, default_stack
from hiyari.bridge.loop.stack.aeb import AEBPlanner, AEBStage, EgoCommand
from hiyari.bridge.loop.stack.interfaces import EgoStack
from hiyari.kinematics import Pose
from hiyari.sensors.outputs import ObjectList
from hiyari.units import G

#: s of simulation time from the first step during which the phantom is braked for.
PHANTOM_SECONDS = 1.2


class PhantomBrake:
    """hiyari's planner, overridden by full AEB braking for PHANTOM_SECONDS."""

    def __init__(self, inner: AEBPlanner) -> None:
        self.inner = inner
        self.acc = inner.acc
        self.aeb = inner.aeb
        self.t0: float | None = None

    def plan(self, tracks: ObjectList, ego: Pose, time: float) -> EgoCommand:
        cmd = self.inner.plan(tracks, ego, time)
        self.t0 = time if self.t0 is None else self.t0
        if time - self.t0 < PHANTOM_SECONDS:
            decel = self.aeb.full_decel_g * G
            return replace(cmd, accel=-decel, aeb_stage=AEBStage.FULL, aeb_decel=decel, ttc=0.5)
        return cmd


def phantom_brake(ctx: StackContext) -> EgoStack:
    """The default stack whose planner brakes on a phantom first."""
    stack = default_stack(ctx)
    return replace(stack, planner=PhantomBrake(stack.planner))
