"""The ego stack of a Euro NCAP test: hiyari's perception, fusion and staged AEB with the ACC's
following off (the protocols test the AEB with a driver holding the test speed, ACC off), or
the user's stack factory (``--stack module:callable``, the contract of ``hiyari evaluate``)."""

from __future__ import annotations

from hiyari.bridge.loop.spec import StackContext, StackFactory, default_perception, load_stack
from hiyari.bridge.loop.stack.aeb import ACCConfig, AEBConfig, AEBPlanner
from hiyari.bridge.loop.stack.fusion import KalmanFusion
from hiyari.bridge.loop.stack.interfaces import EgoStack


def ncap_stack(ctx: StackContext, aeb: AEBConfig | None = None) -> EgoStack:
    """hiyari's stack for a test: the setup's perception, Kalman fusion, speed keeping at the
    test speed and the staged AEB ``aeb`` (None: the defaults with the setup's delay)."""
    planner = AEBPlanner(
        ACCConfig(set_speed=ctx.set_speed, follow=False),
        aeb or AEBConfig(actuation_delay=ctx.setup.aeb_delay),
    )
    return EgoStack(default_perception(ctx), KalmanFusion(), planner)


def stack_factory(spec: str) -> StackFactory:
    """The factory named "module:callable" (empty: :func:`ncap_stack`)."""
    if not spec:
        return ncap_stack
    return load_stack(spec, "--stack")
