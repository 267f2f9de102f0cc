"""The named tables of arrays the engine's compiled passes take, one class per kind of data.

A pass takes a few tables instead of dozens of arrays. Each table is built on the Python side
where its arrays live, once, and kept: the passes update its arrays in place.

A table crosses from Python into compiled code as a plain tuple (``tuple(table)``): numba's
dispatcher types a NamedTuple argument by its class and field names on every call, several
microseconds a table (the quiet step took twice as long), a plain tuple by its items only, as
cheaply as the arrays passed one by one. A kernel that reads a table's fields names them
first (``actors = ActorArrays(*actors)``, free in compiled code); one that only hands a table
on passes it as it came, so that each kernel is compiled for one argument type.

Frames and units: world x, y, z in metres, headings in radians from world +x, speeds m/s,
accelerations m/s^2; road s, t in metres (t to the left of the reference line).
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from hiyari.net.road.lane_profile import LaneProfile
from hiyari.net.road.plan_view import PlanView


class WorldArrays(NamedTuple):
    """The WorldState's arrays the snapshot reads, one entry per SUMO vehicle row."""

    xyz: np.ndarray  # (R, 3) ground-rectangle centre, world m
    heading: np.ndarray  # (R,) rad
    speed: np.ndarray  # (R,) m/s
    accel: np.ndarray  # (R,) m/s^2


class ActorArrays(NamedTuple):
    """The ActorTable's arrays (``motion.ActorTable``), one entry per entity (scenario
    order): kinematic state, road, and the running transitions' parameters."""

    state: np.ndarray  # (len(motion_kernel.STATE), E) float: rows motion_kernel.S ...
    direction: np.ndarray  # (E,) +1 / -1: the actor drives towards increasing / decreasing s
    kappa: np.ndarray  # (E,) reference-line curvature at s before the step, 1/m
    road_code: np.ndarray  # (E,) intp index into the ActorTable's road ids, -1: no road
    lane: np.ndarray  # (E,) int64 OpenDRIVE lane id
    free: np.ndarray  # (E,) bool: off the roads' frames (following a path)
    has_long: np.ndarray  # (E,) bool: a longitudinal transition runs
    long_par: np.ndarray  # (E, 8) its parameters, columns motion_kernel.L_*
    long_done: np.ndarray  # (E,) bool: it ended in the latest pass
    has_lat: np.ndarray  # (E,) bool: a lateral transition runs
    lat_par: np.ndarray  # (E, 9) its parameters, columns motion_kernel.T_*
    lat_done: np.ndarray  # (E,) bool: it ended in the latest pass


def _as_table(name: str, source: type) -> type:
    """A NamedTuple class ``name`` with the fields of dataclass ``source``, in its order (the
    order of its ``arrays()``): the road wing defines them, once."""
    return NamedTuple(name, [(f.name, f.type) for f in dataclasses.fields(source)])


#: The arrays of a LaneProfile (lane offsets and widths of the ActorTable's roads), in the
#: order ``lane_centre_at`` takes them: ``LaneArrays(*profile.arrays())``.
LaneArrays = _as_table("LaneArrays", LaneProfile)
#: The arrays of one road's PlanView (lines and arcs), in the order ``road_pose_at`` takes
#: them: ``RoadArrays(*plan.arrays())``.
RoadArrays = _as_table("RoadArrays", PlanView)


class CommandArrays(NamedTuple):
    """What the command pass reads and writes for the commanded (inserted, driven) actors:
    the last four arrays one entry per commanded row, the others one per entity."""

    rows: np.ndarray  # (m,) intp: the ActorTable rows commanded
    cx: np.ndarray  # (E,) box centre ahead of the reference point, vehicle frame, m
    cy: np.ndarray  # (E,) box centre left of the reference point, m
    length: np.ndarray  # (E,) box length, m
    sent_speed: np.ndarray  # (E,) speed last sent to SUMO, m/s (NaN: none)
    lane_key: np.ndarray  # (E, 3) int64 road code, lane, lane section of the SUMO lane known
    centres: np.ndarray  # (m, 2) box centres, world m
    heading: np.ndarray  # (m,) rad
    send: np.ndarray  # (m,) speed to send, m/s (NaN: unchanged)
    sumo: np.ndarray  # (3, m) front-bumper x, y (m) and SUMO angle (deg clockwise from north)


class GatherArrays(NamedTuple):
    """Where the snapshot gather finds each entity (scenario order)."""

    rows: np.ndarray  # (E,) intp: its row in the WorldState arrays, -1: absent
    centre_offset: np.ndarray  # (E, 2) box centre from the reference point, vehicle frame, m
    own: np.ndarray  # (E,) bool: its road coordinates come from the ActorTable
    driven: np.ndarray  # (E,) bool: the storyboard drives it (its speed's sign from the ActorTable)


class EntityFields(NamedTuple):
    """What the conditions read per entity (scenario order): the arrays of a
    ``snapshot.Snapshot`` and the contact matrix."""

    present: np.ndarray  # (E,) bool
    centre: np.ndarray  # (E, 2) box centre, world m
    ref: np.ndarray  # (E, 2) reference point, world m
    heading: np.ndarray  # (E,) rad
    length: np.ndarray  # (E,) m
    width: np.ndarray  # (E,) m
    speed: np.ndarray  # (E,) m/s
    accel: np.ndarray  # (E,) m/s^2
    on_net: np.ndarray  # (E,) bool: on a SUMO lane
    road_s: np.ndarray  # (E,) road s of the box centre, m (NaN: unknown)
    road_t: np.ndarray  # (E,) road t, m
    road_dir: np.ndarray  # (E,) +1 / -1: driving direction along s
    contact: np.ndarray  # (E, E) bool
    contact_any: np.ndarray  # (E,) bool: in contact with anything
    road_code: np.ndarray  # (E,) float: its road's code in ActorTable.road_ids (-1: none)


class TriggerArrays(NamedTuple):
    """A ``conditions.ConditionBank``'s tables (see trigger_kernel), its tracked state and
    its work arrays (reused, so a step allocates nothing)."""

    cond: np.ndarray  # (C, 7) int64: columns trigger_kernel.C_*
    time_value: np.ndarray  # (C,) s, simulation-time conditions' values
    static: np.ndarray  # (C,) bool: the truth of conditions decided outside the pass
    group_start: np.ndarray  # (G + 1,) first condition of each AND group (last: C)
    trigger_group: np.ndarray  # (T + 1,) first group of each trigger (last: G)
    prev: np.ndarray  # (C,) int8 value at the previous evaluation (-1: none since active)
    history: np.ndarray  # (C, H) bool ring buffer of edged values (delays)
    rows: np.ndarray  # (R, 9) int64 entity rows: columns trigger_kernel.R_*
    row_value: np.ndarray  # (R,) the rows' values
    points: np.ndarray  # (R, 4) world x, y and road s, t of point rows' positions, m (NaN: none)
    since: np.ndarray  # (R, 2) tracked state per row (durations, distance travelled)
    work: np.ndarray  # (E, measures.N_FIELDS) the entities' fields packed
    counts: np.ndarray  # (2, C) int64: rows holding and rows evaluated per condition
    flags: np.ndarray  # (2, C) bool: raw and edged values
    fired: np.ndarray  # (T,) bool: the result
    links: np.ndarray  # (K, K, 2) road b's s in road a's frame: shift, sign (NaN: unlinked)


class ElementArrays(NamedTuple):
    """The storyboard's state the triggers read."""

    active: np.ndarray  # (T,) bool: the triggers being evaluated
    states: np.ndarray  # (N,) element state codes
    transitions: np.ndarray  # (N,) the transition each element went through at the update
