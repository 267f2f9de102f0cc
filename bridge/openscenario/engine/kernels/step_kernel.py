"""A quiet step of the storyboard in one compiled call: the snapshot and the triggers, then,
when no trigger fired, the scripted actors' motion and commands.

A step is quiet when the storyboard changed nothing at the previous update and no action can
end before the motion pass tells so (the executor checks this and keeps the arguments from
step to step: its arrays are updated in place). Python runs between the passes only when a
trigger fired or a transition ended: one call instead of two, with no Python in between.
"""

from __future__ import annotations

import numpy as np

from hiyari.bridge.openscenario.engine.kernels.command_kernel import advance_and_command
from hiyari.bridge.openscenario.engine.kernels.tables import (
    ActorArrays,
    CommandArrays,
    ElementArrays,
    EntityFields,
    GatherArrays,
    LaneArrays,
    RoadArrays,
    TriggerArrays,
    WorldArrays,
)
from hiyari.bridge.openscenario.engine.kernels.trigger_kernel import gather_and_evaluate
from hiyari.jit import njit


@njit(cache=True)
def quiet_step(
    world: WorldArrays,
    now: float,
    step_no: int,
    t_next: float,
    gather: GatherArrays,
    trig: TriggerArrays,
    ent: EntityFields,
    el: ElementArrays,
    rows: np.ndarray,
    dt: float,
    lateral: bool,
    actors: ActorArrays,
    lanes: LaneArrays,
    road: RoadArrays,
    cmd: CommandArrays,
) -> tuple[int, int, int, int, bool, np.ndarray]:
    """``trigger_kernel.gather_and_evaluate`` on the WorldState arrays (``world``) at scenario
    time ``now`` (s), evaluation ``step_no``; then, when no trigger fired,
    ``command_kernel.advance_and_command`` of table ``rows`` to ``t_next`` (s). Returns
    (triggers fired, then advance_and_command's result; zeros, False and no rows when a
    trigger fired: the motion did not run)."""
    n_fired = gather_and_evaluate(now, step_no, world, gather, actors, trig, ent, el)
    if n_fired > 0:
        return n_fired, 0, -1, 0, False, np.empty(0, dtype=np.intp)
    n_long, missing, n_lat, placed, changed = advance_and_command(
        rows, t_next, dt, lateral, actors, lanes, road, cmd
    )
    return n_fired, n_long, missing, n_lat, placed, changed
