"""Ego stacks for the Euro NCAP acceptance tests (``--stack ncap_stacks:NAME`` with tests/ on
the path): hiyari's NCAP stack with a deliberately weaker AEB, and with none."""

from __future__ import annotations

from dataclasses import replace

from hiyari.bridge.loop.spec import StackContext
from hiyari.bridge.loop.stack.aeb import AEBConfig
from hiyari.bridge.loop.stack.interfaces import EgoStack
from hiyari.bridge.studies.ncap.stack import ncap_stack


def _default(ctx: StackContext) -> AEBConfig:
    return AEBConfig(actuation_delay=ctx.setup.aeb_delay)


def half_ttc(ctx: StackContext) -> EgoStack:
    """Every AEB stage at half its TTC threshold."""
    c = _default(ctx)
    weak = replace(c, warning_ttc=c.warning_ttc / 2, partial_ttc=c.partial_ttc / 2,
                   full_ttc=c.full_ttc / 2)  # fmt: skip
    return ncap_stack(ctx, weak)


def late_brake(ctx: StackContext) -> EgoStack:
    """The brake applied 0.3 s later."""
    c = _default(ctx)
    return ncap_stack(ctx, replace(c, actuation_delay=c.actuation_delay + 0.3))


def no_aeb(ctx: StackContext) -> EgoStack:
    """No AEB: no stage is ever reached (the driver holds the test speed)."""
    c = _default(ctx)
    return ncap_stack(ctx, replace(c, warning_ttc=0.0, partial_ttc=0.0, full_ttc=0.0,
                                   hold_after_stop=False))  # fmt: skip
